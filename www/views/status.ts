// The page's state for styles and tests (body[data-state]) and the progress bar.

import { $ } from "./dom";

export function setState(state: "loading" | "reading" | "idle" | "slicing" | "done" | "error" | "cancelled"): void {
  document.body.dataset.state = state;
}

export function progress(fraction: number | null, label = "Slicing…"): void {
  const p = $("progress");
  if (fraction === null) {
    p.hidden = true;
    return;
  }
  p.hidden = false;
  const pct = Math.floor(fraction * 100);
  $("progress-label").textContent = label;
  $("progress-pct").textContent = `${pct} %`;
  $("progress-fill").style.transform = `scaleX(${pct / 100})`;
  p.dataset.percent = String(pct);
}

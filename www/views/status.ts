// The page's state for styles and tests (body[data-state]) and the progress bar.

import { $, setText } from "./dom";

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
  // only what changed (setText): the bar moves every 150 ms while slicing
  setText("progress-label", label);
  setText("progress-pct", `${pct} %`);
  $("progress-fill").style.transform = `scaleX(${pct / 100})`;
  p.dataset.percent = String(pct);
}


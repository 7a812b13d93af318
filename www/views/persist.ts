// The notice of the job kept in the browser (flows/persist.ts): the job from last time restored
// (with *Start over*), a kept job that could not be read, a job too big to keep, a preview
// link's job become the visitor's own.

import { $ } from "./dom";

/** Shows `text`; with `startOver`, the *Start over* button. */
export function persistNotice(text: string, startOver = false, tone: "info" | "warn" = "info"): void {
  $("persist-text").textContent = text;
  $("persist-start-over").hidden = !startOver;
  const el = $("persist-note");
  // the banner's own colours are the warning's
  el.classList.toggle("info", tone === "info");
  el.hidden = false;
}

export function hidePersistNotice(): void {
  $("persist-note").hidden = true;
}

/** The notice's buttons: *Start over* runs `startOver`; ✕ dismisses it. */
export function wirePersistNotice(startOver: () => void): void {
  $("persist-start-over").addEventListener("click", startOver);
  $("persist-close").addEventListener("click", hidePersistNotice);
}

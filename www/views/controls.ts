// The buttons Download, Copy preview link and Slice, and the settings' status line.

import { jobSettings } from "../core/job";
import type { Page } from "./page";
import { $ } from "./dom";

export function updateButtons(page: Page): void {
  const { store, form } = page;
  const s = store.slice;
  const ready = !store.busy && s !== null && s.complete;
  // Like the CLI, no code for a part without a single droplet.
  ($("btn-download") as HTMLButtonElement).disabled = !(ready && s!.source === "stl" && !s!.figures.nothingToPrint);
  ($("btn-share") as HTMLButtonElement).disabled = !(ready && s!.source === "stl" && s!.job !== null);
  ($("btn-slice") as HTMLButtonElement).disabled = store.job === null || form === undefined;
  // the support switch shows the setting (a link, a job file or the form may have set it)
  if (form) $<HTMLInputElement>("opt-support").checked = form.get("support") === "unit1";
  settingsStatus(page);
}

function settingsStatus(page: Page): void {
  const { store, form } = page;
  if (!form) return;
  const st = $("settings-status");
  const errors = form.errors();
  const btn = $("btn-slice");
  if (errors.length) {
    st.textContent = `${errors.length} setting${errors.length > 1 ? "s are" : " is"} invalid.`;
    st.className = "hint bad";
    ($("btn-slice") as HTMLButtonElement).disabled = true;
    btn.classList.remove("attention");
    return;
  }
  const job = store.job;
  const slice = store.slice;
  const schema = page.init!.schema;
  const settings = jobSettings(form.values(), schema);
  const stale = job !== null && !store.busy && (slice?.source !== "stl" || job.key(settings) !== slice.key);
  const settingsChanged = slice?.source === "stl" && JSON.stringify(settings) !== JSON.stringify(jobSettings(slice.settings, schema));
  st.className = "hint";
  st.textContent = !stale ? "" : settingsChanged ? "Settings changed: press Slice (or Enter) to update." : "The parts changed: press Slice (or Enter) to update.";
  btn.classList.toggle("attention", stale);
}

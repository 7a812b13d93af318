// The buttons Download, Copy preview link and Slice, the settings' status line, and the marks
// of a slice that no longer belongs to the job on screen. What is downloaded or linked is
// always the job on screen: the two buttons are enabled only while the slice is of the job and
// the settings as they are now (after a change, Slice first), and never for a job with a part
// off the plate.

import { jobSettings } from "../core/job";
import { jobOffPlate } from "../core/plate";
import { isSettingName, type Settings } from "../core/settings";
import { supportUnit, unitsOf } from "../core/units";
import type { Page } from "./page";
import { $ } from "./dom";

/** "current": the slice shown is of the job as it is; "stale": of an earlier state of it (or of
 *  another job); "none": no slice, or one still being made. */
export function sliceState(page: Page): "current" | "stale" | "none" {
  const { store, form, init } = page;
  const s = store.slice;
  if (!s || s.source !== "stl" || store.busy) return "none";
  const job = store.job;
  if (!job || !form || !init) return "stale";
  return s.key === job.key(jobSettings(form.values())) ? "current" : "stale";
}

/** The derived figures (statistics, plot, layer figures, calibration) marked out of date. */
function markStale(stale: boolean): void {
  document.body.dataset.slice = stale ? "stale" : "ok";
  for (const el of [$("stats-panel"), document.querySelector(".plotbar"), document.querySelector(".layerbar"), $("calib")]) {
    if (el instanceof HTMLElement) el.toggleAttribute("data-stale", stale);
  }
  $("stale-note").hidden = !stale;
}

export function updateButtons(page: Page): void {
  const { store, form } = page;
  const s = store.slice;
  const state = sliceState(page);
  markStale(state === "stale");
  const off = jobOffPlate(store.job, form?.values());
  const ready = !store.busy && s !== null && s.complete && (s.source === "gco" || (state === "current" && off.length === 0));
  const why = state === "stale" ? "The slice is out of date: press Slice first" : off.length ? off[0].message : "";
  // Like the CLI, no code for a part without a single droplet.
  const download = $<HTMLButtonElement>("btn-download");
  download.disabled = !(ready && s!.source === "stl" && !s!.figures.nothingToPrint);
  download.title = why || "Save the G-code of this slice";
  const share = $<HTMLButtonElement>("btn-share");
  share.disabled = !(ready && s!.source === "stl" && s!.job !== null);
  share.title = why || "Copy a link that opens this slice (settings, parts, view)";
  $<HTMLButtonElement>("btn-slice").disabled = store.job === null || form === undefined || off.length > 0 || !store.job.layout;
  if (form) writeUnits(page, form.values());
  settingsStatus(page, state === "stale", off.map((o) => o.message));
  formSource(page);
}

/** An opened .gco file: the form shows the settings its header names (flows/slice.ts put
 *  them there), or says plainly that it shows others, and which. */
function formSource(page: Page): void {
  const el = $("form-source");
  const s = page.store.slice;
  const g = s?.source === "gco" ? s.gcodeFile : null;
  const form = page.form;
  el.hidden = !g || !form;
  if (!g || !form) {
    el.textContent = "";
    delete el.dataset.state;
    return;
  }
  const name = `“${s!.name}”`;
  if (!g.settings) {
    el.textContent = `The settings form shows the page's settings, not those of ${name}: ${g.settingsError ?? "its header gives none"}.`;
    el.dataset.state = "none";
    return;
  }
  // a name the form does not know is not compared
  const differ = Object.entries(g.settings).flatMap(([k, v]) => (isSettingName(k) && form.get(k) !== v ? [{ k, v }] : []));
  if (differ.length === 0) {
    el.textContent = `The settings form shows the settings of ${name} (from its header).`;
    el.dataset.state = "file";
    return;
  }
  const shown = differ.slice(0, 3).map(({ k, v }) => `${k} is ${String(form.get(k))} here, ${String(v)} in the file`);
  const more = differ.length > 3 ? ` and ${differ.length - 3} more` : "";
  el.textContent = `The settings form differs from ${name}: ${shown.join("; ")}${more}.`;
  el.dataset.state = "differs";
}

function settingsStatus(page: Page, stale: boolean, offPlate: string[]): void {
  const { store, form } = page;
  if (!form) return;
  const st = $("settings-status");
  const errors = form.errors();
  const btn = $("btn-slice");
  const bad = (text: string) => {
    st.textContent = text;
    st.className = "hint bad";
    ($("btn-slice") as HTMLButtonElement).disabled = true;
    btn.classList.remove("attention");
  };
  if (errors.length) return bad(`${errors.length} setting${errors.length > 1 ? "s are" : " is"} invalid.`);
  if (offPlate.length) return bad(offPlate.length > 1 ? `${offPlate[0]} (and ${offPlate.length - 1} more off the plate)` : offPlate[0]);
  const job = store.job;
  if (job && !job.layout && !store.busy) return bad("The parts do not fit on the plate together: remove, scale or make fewer copies of some.");
  const slice = store.slice;
  const settings = jobSettings(form.values());
  const unsliced = job !== null && !store.busy && slice?.source !== "stl";
  const settingsChanged = slice?.source === "stl" && JSON.stringify(settings) !== JSON.stringify(jobSettings(slice.settings));
  st.className = "hint";
  st.textContent = !(stale || unsliced) ? "" : settingsChanged ? "Settings changed: press Slice (or Enter) to update." : "The parts changed: press Slice (or Enter) to update.";
  btn.classList.toggle("attention", stale || unsliced);
}

/** The unit the support switch turns on: the last `support = unitN` the form had (unit 1 at
 *  first). */
let supportBy = 1;
let shownUnits = 0;

/** The switch's `support` value when it is turned on (main.ts). */
export const supportOn = (): Settings["support"] => `unit${supportBy}` as Settings["support"];

/** What follows the machine's units (the form's `units`) and the support's unit: the support
 *  switch (a link, a job file or the form may have set `support`; with one unit there is no
 *  unit to print support), and, when the count changed, the form's unit groups, the parts
 *  panel's unit choice and the 3D view's legend. */
function writeUnits(page: Page, values: Settings): void {
  const n = unitsOf(values);
  const by = supportUnit(values.support);
  if (by !== null) supportBy = by;
  if (supportBy >= n) supportBy = 1;
  $<HTMLInputElement>("opt-support").checked = by !== null;
  const name = `Support (unit ${by ?? supportBy})`;
  if ($("opt-support-name").textContent !== name) {
    $("opt-support-name").textContent = name;
    $("support-switch").title = `Print support under every overhang with discharge unit ${by ?? supportBy} (the setting support = unit${by ?? supportBy}; its details are in the Support group)`;
  }
  $("support-switch").hidden = n === 1 && by === null;
  if (n === shownUnits) return;
  shownUnits = n;
  page.form?.showUnits(n);
  page.parts.render();
  page.view3d.sync(page);
}

// Undo and redo over every change of the build job and the settings (core/history.ts keeps the
// snapshots): each change is recorded once it is made (a part edit once the core accepted it,
// a new job once it is the page's, a setting as it is typed: typing on in the same field
// amends the same entry); undo and redo put a snapshot back (settings, files, parts, the
// selection) and have the core lay it out again. The slice is not touched: when the state put
// back is the one sliced, the slice is current again.

import { snapshotOf, type Snapshot } from "../core/history";
import type { Value } from "../core/settings";
import { updateButtons } from "../views/controls";
import { undoNotice, updateUndo } from "../views/notices";
import type { Page } from "../views/page";
import { adoptJob, ensureMeshes, layoutBanner, hideLayoutBanner, settingsOf } from "./job";
import { jobChanged } from "./persist";

/** Typing on in the same setting within this time amends its entry. */
const AMEND_MS = 1500;

/** The last settings entry: which settings it changed and when (to amend it). */
let lastSettings: { names: string; at: number } | null = null;
/** Set while the page itself sets the form (restore, reset): no entry of its own. */
let quiet = false;

/** Records the state now as the result of the change `label`: `edit` (the job changed: leaving
 *  the page asks), `open` (a new job) or `settings`. */
export function record(page: Page, label: string, kind: "edit" | "open" | "settings" = "edit"): void {
  if (!page.form) return;
  if (kind !== "settings") lastSettings = null;
  page.history.commit(snapshotOf(page.store.job, page.form.values()), label);
  if (kind === "edit") page.store.edited = true;
  else if (kind === "open") page.store.edited = false;
  updateUndo(page);
  // kept in the browser (flows/persist.ts)
  jobChanged(page, label);
}

/** The names of the settings that differ between `a` and `b`. */
function changedNames(a: Record<string, Value>, b: Record<string, Value>): string[] {
  return Object.keys(b).filter((k) => a[k] !== b[k]);
}

/** A setting was changed in the form (called on every input): recorded, or amended while the
 *  same setting is typed on. */
export function settingsChanged(page: Page): void {
  const form = page.form;
  const before = page.history.present;
  if (quiet || !form || !before) return;
  const values = form.values();
  const names = changedNames(before.settings, values);
  if (names.length === 0) return;
  const key = names.join();
  const now = performance.now();
  if (lastSettings && lastSettings.names === key && now - lastSettings.at < AMEND_MS) {
    page.history.amend(snapshotOf(page.store.job, values));
    lastSettings.at = now;
    return;
  }
  record(page, names.length === 1 ? `change ${names[0].replace(/_/g, " ")}` : `change ${names.length} settings`, "settings");
  lastSettings = { names: key, at: now };
}

/** Every setting back to its default, as one undoable change. */
export function resetSettings(page: Page): void {
  const form = page.form;
  if (!form) return;
  quiet = true;
  try {
    form.reset();
  } finally {
    quiet = false;
  }
  record(page, "reset settings to defaults", "settings");
  updateButtons(page);
}

export function undo(page: Page): Promise<void> {
  return step(page, "undo");
}

export function redo(page: Page): Promise<void> {
  return step(page, "redo");
}

async function step(page: Page, which: "undo" | "redo"): Promise<void> {
  lastSettings = null;
  const e = which === "undo" ? page.history.undo() : page.history.redo();
  updateUndo(page);
  if (!e) return;
  await restore(page, page.history.present!);
  page.store.edited = true;
  jobChanged(page);
  undoNotice(page, which === "undo" ? `Undone: ${e.label}` : `Redone: ${e.label}`, which === "undo" ? "redo" : "undo");
}

/** Puts `snap` back: the settings into the form, the job's files, parts and selection (laid
 *  out again by the core; a state that did not fit comes back without a layout, as it was). */
async function restore(page: Page, snap: Snapshot): Promise<void> {
  const { store } = page;
  const form = page.form!;
  quiet = true;
  try {
    form.set(snap.settings);
  } finally {
    quiet = false;
  }
  const job = snap.job;
  if (!job) {
    updateButtons(page);
    return;
  }
  for (const m of snap.models) job.models.set(m.name, m);
  const seq = ++store.layoutSeq;
  let refusal: unknown = null;
  let layout = null;
  try {
    layout = await page.pool.layout(job.refs(snap.parts), job.file(settingsOf(page), snap.parts));
  } catch (e) {
    refusal = e;
  }
  if (seq !== store.layoutSeq) return;
  job.parts = snap.parts;
  job.layout = layout;
  job.selected = snap.selected;
  job.prune();
  if (refusal) layoutBanner(refusal);
  else hideLayoutBanner();
  if (store.job !== job) adoptJob(page, job);
  page.parts.render();
  page.view3d.sync(page);
  page.renderer.request();
  void ensureMeshes(page);
  updateButtons(page);
}

// Undo and redo over every change of the build job and the settings (flows/record.ts records
// them; core/history.ts keeps the snapshots): undo and redo put a snapshot back (settings,
// files, parts, the selection) and have the core lay it out again. The slice is not touched:
// when the state put back is the one sliced, the slice is current again.

import type { Snapshot } from "../core/history";
import { updateButtons } from "../views/controls";
import { undoNotice, updateUndo } from "../views/notices";
import type { Page } from "../views/page";
import { adoptJob, ensureMeshes, layoutBanner, hideLayoutBanner, settingsOf } from "./job";
import { jobChanged } from "./persist";
import { endAmend, quietly } from "./record";

export function undo(page: Page): Promise<void> {
  return step(page, "undo");
}

export function redo(page: Page): Promise<void> {
  return step(page, "redo");
}

async function step(page: Page, which: "undo" | "redo"): Promise<void> {
  endAmend();
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
  quietly(() => form.set(snap.settings));
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

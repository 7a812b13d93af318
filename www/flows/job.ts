// The build job's runs: a new job of files, adding parts, every edit of a part (re-laid out by
// the core at once; refused edits leave the job as it was), selection, lay flat, duplicate,
// remove, arrange, the display meshes of the 3D view, and saving the job file. The slice of a
// job: flows/slice.ts startSlice.

import type { Page } from "../views/page";
import { DISPLAY_BUDGET, Job, jobSettings, layFlatAngles, meshKey, partName, specOut, uniqueName, type Changes, type DisplayMesh, type JobModel, type Part, type Spec } from "../core/job";
import type { Orientation, Orientations, PartSpec } from "../core/protocol";
import { nonDefault } from "../core/settings";
import { errorBanner, hideBanner } from "../views/banner";
import { updateButtons } from "../views/controls";
import { saveFile } from "../views/download";
import { SliceError } from "../core/client";
import { grouped } from "../core/grouped";
import { restoreModel, showError } from "./errors";
import { record } from "./record";

/** A file to add to a job: the File and, from a job file or a link, the name it has there. */
export interface NewFile {
  file: File;
  name?: string;
}

/** Imports `files` into the job worker under names unique in `job` (a job's own names kept
 *  when given); returns the job's models, or throws the core's error (nothing changed). */
async function importFiles(page: Page, job: Job, files: NewFile[]): Promise<JobModel[]> {
  const taken = new Set(job.models.keys());
  const named = files.map((f) => {
    const name = f.name ?? uniqueName(f.file.name, (n) => taken.has(n));
    taken.add(name);
    return { name, file: f.file };
  });
  const { infos, sha256 } = await page.pool.addModels(named);
  return named.map((f, i) => ({ name: f.name, file: f.file, sha256: sha256[i], info: infos[i] }));
}

/** A new job of `files` (one part each: a 3MF's whole build is one part), or of the parts
 *  `specs` (a job file or a link; their `file` names the files). Laid out by the core. When a
 *  file cannot be read, or a job file's parts are refused, the banner says why and the page
 *  keeps its current job (null). Files that do not fit the plate together still make the job
 *  (without a layout, the banner says what does not fit) so that its parts can be changed;
 *  so do the parts `specs` with `keepUnfit` (the job kept from last time, flows/persist.ts). */
export async function newJob(page: Page, files: NewFile[], specs?: PartSpec[], keepUnfit = specs === undefined): Promise<Job | null> {
  const job = new Job();
  let parts: Part[];
  try {
    for (const m of await importFiles(page, job, files)) job.models.set(m.name, m);
    parts = (specs ?? [...job.models.values()].map((m) => ({ file: m.name }))).map((s) => job.newPart(s));
  } catch (e) {
    showError(page, e);
    return null;
  }
  try {
    job.layout = await page.pool.layout(job.refs(parts), job.file(settingsOf(page), parts));
    job.parts = parts;
  } catch (e) {
    if (!keepUnfit || !(e instanceof SliceError) || e.kind !== "job") {
      showError(page, e);
      return null;
    }
    job.parts = parts;
    layoutBanner(e);
  }
  return job;
}

/** A layout's refusal: shown until a layout succeeds. */
export function layoutBanner(e: unknown): void {
  errorBanner(e);
  document.getElementById("banner")!.dataset.layout = "1";
}

/** Makes `job` the page's job: the panel, the 3D view, the meshes. */
export function adoptJob(page: Page, job: Job): void {
  page.store.job = job;
  page.store.pending = null;
  page.parts.render();
  page.view3d.sync(page);
  void ensureMeshes(page);
  updateButtons(page);
}

export function settingsOf(page: Page) {
  return jobSettings(page.form!.values());
}

/**
 * Lays out `parts` (the job's parts after an edit) and, when the core accepts them, makes them
 * the job's parts (the 3D view, the panel and the Slice button follow). When it refuses (a job
 * that does not fit, a value out of range) its message is shown and nothing changes. Only the
 * latest of overlapping requests is applied. Returns whether the parts were taken. A change
 * taken is recorded for undo as `label` (null: not recorded, the job is as it was).
 */
export async function applyParts(page: Page, parts: Part[], label: string | null = "edit part"): Promise<boolean> {
  const { store } = page;
  const job = store.job;
  if (!job) return false;
  const seq = ++store.layoutSeq;
  try {
    const layout = await page.pool.layout(job.refs(parts), job.file(settingsOf(page), parts));
    if (seq !== store.layoutSeq || store.job !== job) return false;
    job.parts = parts;
    job.layout = layout;
    if (job.part(job.selected) === undefined) job.selected = null;
    job.prune();
    hideLayoutBanner();
  } catch (e) {
    if (seq === store.layoutSeq && store.job === job) {
      layoutBanner(e);
      page.parts.render();
    }
    return false;
  }
  page.parts.render();
  page.view3d.sync(page);
  page.renderer.request();
  void ensureMeshes(page);
  updateButtons(page);
  if (label !== null) record(page, label);
  return true;
}

/** A layout error's banner goes once a layout succeeds. */
export function hideLayoutBanner(): void {
  const b = document.getElementById("banner")!;
  if (b.dataset.layout === "1") {
    delete b.dataset.layout;
    hideBanner();
  }
}

/** The job laid out again as it is (the plate or the spacing changed in the form). */
export function relayout(page: Page): Promise<boolean> {
  const job = page.store.job;
  if (!job || page.form!.errors().length) return Promise.resolve(false);
  return applyParts(page, job.parts, null);
}

export function editParts(page: Page, edits: { id: number; changes: Changes }[], label = "edit part"): Promise<boolean> {
  const job = page.store.job;
  if (!job) return Promise.resolve(false);
  const parts = job.parts.map((p) => {
    const e = edits.find((x) => x.id === p.id);
    if (!e) return p;
    const spec: Spec = { ...p.spec };
    const { place, ...changes } = e.changes;
    Object.assign(spec, changes);
    if (place === null) {
      delete spec.place_x;
      delete spec.place_y;
    }
    return { ...p, spec };
  });
  return applyParts(page, parts, label);
}

export function selectPart(page: Page, id: number | null): void {
  const job = page.store.job;
  if (!job || (id !== null && !job.part(id))) return;
  job.selected = id;
  page.parts.render();
  page.view3d.sync(page);
  page.renderer.request();
}

/** Adds files to the current job as new parts (arranged). */
export async function addParts(page: Page, files: File[]): Promise<void> {
  const job = page.store.job;
  if (!job) return;
  let models: JobModel[];
  try {
    models = await importFiles(page, job, files.map((file) => ({ file })));
  } catch (e) {
    showError(page, e);
    return;
  }
  for (const m of models) job.models.set(m.name, m);
  const added = models.map((m) => job.newPart({ file: m.name }));
  if (await applyParts(page, [...job.parts, ...added], added.length > 1 ? `add ${added.length} parts` : "add part")) {
    selectPart(page, added[added.length - 1].id);
  } else {
    // refused (does not fit): the files go again
    job.prune();
  }
}

export function duplicatePart(page: Page, id: number): void {
  const job = page.store.job;
  const p = job?.part(id);
  if (!job || !p) return;
  const copy = job.newPart(specOut(p.spec));
  // a copy of a placed part is arranged (it would lie on the original)
  delete copy.spec.place_x;
  delete copy.spec.place_y;
  const at = job.parts.indexOf(p) + 1;
  void applyParts(page, [...job.parts.slice(0, at), copy, ...job.parts.slice(at)], "duplicate part").then((ok) => ok && selectPart(page, copy.id));
}

export function removePart(page: Page, id: number): void {
  const job = page.store.job;
  if (!job || job.parts.length <= 1) return;
  const p = job.part(id);
  if (!p) return;
  void applyParts(page, job.parts.filter((q) => q !== p), `remove ${partName(job, p)}`);
}

/** Every placement cleared: the core arranges all parts. */
export function arrangeAll(page: Page): void {
  const job = page.store.job;
  if (!job) return;
  void editParts(page, job.parts.map((p) => ({ id: p.id, changes: { place: null } })), "arrange");
}

/** The core's lay-flat angles put into the part (its z rotation, scale and mirror kept: with a
 *  z mirror the angles that put the face down through it, `layFlatAngles`). */
export async function layFlat(page: Page, id: number): Promise<void> {
  const job = page.store.job;
  const p = job?.part(id);
  if (!job || !p) return;
  try {
    const a = await page.pool.layFlat(job.refs(), p.spec.file, p.spec.item);
    await editParts(page, [{ id, changes: layFlatAngles(a, p.spec.mirror_z) }], "lay flat");
  } catch (e) {
    showError(page, e);
  }
}

/** The part's candidate orientations (the core's, by the overhang rule), best first. */
export function orientations(page: Page, id: number): Promise<Orientations> {
  const job = page.store.job;
  const p = job?.part(id);
  if (!job || !p) return Promise.reject(new Error("the part is no longer in the job"));
  return page.pool.orient(job.refs(), job.file(settingsOf(page)), job.parts.indexOf(p));
}

/** Stops an Orient under way (no slice running): the job worker, busy in the core's long
 *  call, is replaced by a fresh one, which gets the job's files again with its next request;
 *  the part stays as it was. A finished slice's model is opened again if no worker holds it. */
export function cancelOrient(page: Page): void {
  if (!page.pool.restartJobWorker()) restoreModel(page);
}

/** The part turned to the orientation `o` picked (its scale and placement kept). */
export function applyOrientation(page: Page, id: number, o: Orientation): Promise<boolean> {
  return editParts(page, [{ id, changes: { rotate_x: o.rotate_x, rotate_y: o.rotate_y, rotate_z: o.rotate_z } }], "orient");
}

/** A drag in the 3D view (or the layer view) ended: the part's first copy goes where the
 *  dragged instance was dropped. */
export function movePart(page: Page, id: number, copy: number, dx: number, dy: number): Promise<boolean> {
  const job = page.store.job;
  const inst = job?.layout?.instances.find((x) => job.parts[x.part]?.id === id && x.copy === copy);
  if (!job || !inst || !Number.isFinite(dx + dy)) return Promise.resolve(false);
  const round = (v: number) => Math.round(v * 100) / 100;
  return editParts(page, [{ id, changes: { place_x: round(inst.at[0] + dx), place_y: round(inst.at[1] + dy) } }], "move part");
}

/** Fetches the display meshes the 3D view lacks: the job's budget shared by its instances
 *  (parts of many copies are drawn coarser); a mesh far off its share is fetched again. Only
 *  while the 3D view is shown (it asks when it is opened): the job worker makes them, and a
 *  mesh asked for with a new job would delay that worker's preparation of the slice (0.7 s
 *  for a part of a million facets). */
export async function ensureMeshes(page: Page): Promise<void> {
  const job = page.store.job;
  if (!job || !page.view3d.active) return;
  const budget = Math.max(2000, Math.floor(DISPLAY_BUDGET / Math.max(1, job.instances)));
  const stale = (m: DisplayMesh | null) => !m || m.budget > 2 * budget || (m.budget < budget / 2 && m.positions.length / 9 >= m.budget * 0.8);
  // parts of the same file and item share one mesh (the job's, never a part's)
  const want = grouped(job.parts.filter((p) => stale(job.meshOf(p))), (p) => meshKey(p.spec));
  for (const [key, parts] of want) {
    const p = parts[0];
    try {
      const positions = await page.pool.displayMesh(job.refs(), p.spec.file, p.spec.item, budget);
      if (page.store.job !== job) return;
      // a part of this file and item is still in the job (an undo may have taken it away)
      if (job.parts.some((q) => meshKey(q.spec) === key)) job.meshes.set(key, { positions, budget });
      page.view3d.sync(page);
    } catch (e) {
      if (page.store.job === job) showError(page, e);
      return;
    }
  }
}

/** The job file (docs/jobs.md): the settings that differ from the defaults and the parts. */
export function jobFileText(page: Page): string | null {
  const job = page.store.job;
  if (!job) return null;
  const settings = nonDefault(settingsOf(page));
  return JSON.stringify({ settings, parts: job.parts.map((p) => specOut(p.spec)) }, null, 2) + "\n";
}

export function saveJob(page: Page): void {
  const text = jobFileText(page);
  const job = page.store.job;
  if (!text || !job) return;
  saveFile(new Blob([text], { type: "application/json" }), "job.json");
}

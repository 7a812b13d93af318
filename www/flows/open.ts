// Opening what the user gives the page: files (models become a new build job; a .gco file is
// viewed; a job file opens its job and asks for its models), the sample part, or the preview
// link in the URL (its job and, when they fit, its models). A job waiting for its models (a
// job file, a link too big for them) takes the files dropped next: by name for a job file, by
// SHA-256 for a link. Each ends in a flow of slice.ts.

import { DEFAULTS, type RawSettings, type SomeSettings, type Spec, type Value } from "../core/settings";
import { dropSlice, openGcode, startSlice, type Target } from "./slice";
import { record } from "./record";
import { jobSettings, partKeysOf } from "../core/job";
import { jobOffPlate } from "../core/plate";
import { adoptJob, newJob, type NewFile } from "./job";
import type { Page } from "../views/page";
import type { JobFile, JobSchema, PartSpec } from "../core/protocol";
import { sampleStl } from "../core/sample";
import { LinkError, readLink, type Overlays, type ShareState, type SharedLink } from "../core/share";
import type { PendingJob } from "../core/store";
import { note, showBanner, TITLES } from "../views/banner";
import { updateButtons } from "../views/controls";
import { nf } from "../views/dom";
import { setLine } from "../views/cut";
import { setOverlay, setShowTravel } from "../views/layer";
import { linkFromNote, undoNotice } from "../views/notices";
import { showModel } from "../views/stats";
import { setState } from "../views/status";

/** The label of a preview link's own opening: not the visitor's edit (flows/persist.ts). */
export const LINK_OPEN_LABEL = "open the preview link";

/** The longest model file name a job file's part may give (a file system's limit). */
const FILE_NAME_MAX = 255;

const isGcode = (f: File) => /\.(gco|gcode)$/i.test(f.name);
const isJobFile = (f: File) => /\.json$/i.test(f.name);

/** Files opened (the picker or a drop): a .gco file is viewed on its own; a job file opens
 *  its job with the models given along (and asks for the others); models make a new job, or
 *  complete the job waiting for its models. */
export async function openFiles(page: Page, files: File[]): Promise<void> {
  const store = page.store;
  if (files.length === 0) return;
  const chosen = performance.now();
  setState("reading");
  const gcode = files.find(isGcode);
  if (gcode) {
    store.pending = null;
    note(files.length > 1 ? `A .gco file is viewed on its own: only “${gcode.name}” was opened.` : "", files.length > 1 ? "warn" : "none");
    await openGcode(page, gcode);
    return;
  }
  store.fileChosenAt = chosen;
  const jobFile = files.find(isJobFile);
  const models = files.filter((f) => !isJobFile(f));
  if (jobFile) {
    const job = await readJobFile(jobFile, page.init!.job);
    if (typeof job === "string") {
      showBanner(TITLES.job, job);
      setState("error");
      return;
    }
    note("", "none");
    await openPending(page, pendingOf(job), models);
    return;
  }
  if (store.pending) {
    await openPending(page, store.pending, models);
    return;
  }
  note("", "none");
  await openJob(page, models.map((file) => ({ file })), undefined, {}, models.length === 1 ? `open ${models[0].name}` : `open ${models.length} files`);
}

/** A new job of `files` (or of `specs`), sliced at once; 3D first when it has several
 *  instances. */
async function openJob(page: Page, files: NewFile[], specs?: PartSpec[], target: Target = {}, what = "open files", keepUnfit = specs === undefined): Promise<boolean> {
  const job = await newJob(page, files, specs, keepUnfit);
  if (!job) return false;
  const before = page.store.job;
  adoptJob(page, job);
  record(page, what, "open");
  // the job replaced is one Undo away
  if (before && before.parts.length) undoNotice(page, `“${job.name}” replaced the previous job.`);
  if (job.instances > 1) page.view3d.setActive(true);
  if (!job.layout || jobOffPlate(job, page.form?.values()).length) {
    // the parts do not fit (together, or one of them the plate): the banner says so, with
    // what fits in the parts panel; change them, then slice. The slice shown was of the job
    // before: it goes with it, its name too (never the new parts with the old code)
    dropSlice(page);
    showModel(job.name);
    if (job.layout) await startSlice(page, target);
    else setState("error");
    updateButtons(page);
    return true;
  }
  await startSlice(page, target);
  return true;
}


/** The job kept from last time (flows/persist.ts): its files under their names and its parts,
 *  sliced at once like any job opened; parts that do not fit the plate come back as they were
 *  left (the banner says so). False when the core refused it (its message shown). */
export function openStored(page: Page, files: NewFile[], parts: PartSpec[], target: Target = {}): Promise<boolean> {
  note("", "none");
  return openJob(page, files, parts, target, "open the job from last time", true);
}

/** Reads a job file (on the page's thread, at most the core's `max_job_file_bytes`) into its
 *  JSON; a message when it is not one. The core checks every field when the job is laid out. */
async function readJobFile(file: File, limits: JobSchema): Promise<JobFile | string> {
  const maxBytes = limits.max_job_file_bytes;
  if (file.size > maxBytes) return `“${file.name}” is ${nf.format(file.size)} bytes; a job file has at most ${nf.format(maxBytes)}.`;
  let raw: unknown;
  try {
    raw = JSON.parse(await file.text());
  } catch (e) {
    return `“${file.name}” is not a job file: it is not JSON (${e instanceof Error ? e.message : String(e)}).`;
  }
  const obj = raw as { settings?: unknown; parts?: unknown };
  if (typeof raw !== "object" || raw === null || Array.isArray(raw)) return `“${file.name}” is not a job file: it must be an object {"settings": {…}, "parts": [{"file": "a.stl"}, …]}.`;
  if (!Array.isArray(obj.parts) || obj.parts.length === 0) return `“${file.name}” lists no parts: a job file has "parts": [{"file": "a.stl"}, …].`;
  const maxParts = limits.max_parts;
  if (obj.parts.length > maxParts) return `“${file.name}” lists ${nf.format(obj.parts.length)} parts; at most ${maxParts} are allowed.`;
  const parts = obj.parts as unknown[];
  const bad = parts.findIndex((p) => typeof p !== "object" || p === null || typeof (p as { file?: unknown }).file !== "string" || (p as { file: string }).file.length > FILE_NAME_MAX);
  if (bad >= 0) return `“${file.name}”: parts[${bad}] has no "file" (the model's file name, at most ${FILE_NAME_MAX} characters).`;
  const settings = obj.settings === undefined || obj.settings === null ? {} : obj.settings;
  if (typeof settings !== "object" || Array.isArray(settings)) return `“${file.name}”: "settings" must be an object {"name": value, …}.`;
  return { settings: settings as RawSettings, parts: parts as PartSpec[] };
}

function pendingOf(job: JobFile, link?: ShareState): PendingJob {
  if (link?.files) {
    return { source: "link", job, link, files: link.files.map((f) => ({ name: f.name, sha256: f.sha256 })) };
  }
  const names = [...new Set(job.parts.map((p) => p.file))];
  return { source: link ? "link" : "file", job, link, files: names.map((name) => ({ name, sha256: link && name === link.name ? link.sha256 : undefined })) };
}

/** Gives a waiting job the files `dropped`; opens it when none is missing any more, else says
 *  which are. A job file's files are matched by name (the file name alone, any folder), a
 *  link's by SHA-256. */
async function openPending(page: Page, pending: PendingJob, dropped: File[]): Promise<void> {
  const { store } = page;
  const strangers: File[] = [];
  for (const f of dropped) {
    let slot: PendingJob["files"][number] | undefined;
    if (pending.source === "link") {
      const sha = await page.pool.hash(f).catch(() => "");
      slot = pending.files.find((x) => !x.file && x.sha256 !== undefined && sha !== "" && sha.startsWith(x.sha256));
    } else {
      slot = pending.files.find((x) => x.name === f.name) ?? pending.files.find((x) => baseOf(x.name) === f.name);
    }
    if (slot) slot.file = f;
    else strangers.push(f);
  }
  const missing = pending.files.filter((x) => !x.file);
  const link = pending.link;
  const target: Target = link ? { layer: link.layer, view: link.view } : {};
  // a link of one model: a different file is sliced with the link's settings, and said so
  if (missing.length === 1 && pending.files.length === 1 && pending.source === "link" && strangers.length === 1) {
    store.pending = null;
    const name = pending.files[0].name;
    note(`“${strangers[0].name}” does not match the model of the preview link (“${name}”, SHA-256 ${(pending.files[0].sha256 ?? "").slice(0, 12)}…): this is a different file. It is sliced with the link's settings.`, "warn");
    const job = { ...pending.job, parts: pending.job.parts.map((p) => ({ ...p, file: strangers[0].name })) };
    await openJob(page, [{ file: strangers[0] }], job.parts, {}, LINK_OPEN_LABEL);
    return;
  }
  if (missing.length === 0) {
    // a link's settings are in the form already
    if (pending.source === "file") applyJobSettings(page, pending.job.settings);
    if (pending.source === "link") note(pending.files.length > 1 ? "The dropped files match the models of the preview link." : `“${pending.files[0].file!.name}” matches the model of the preview link.`, "ok");
    const extra = strangers.length ? ` (not part of it: ${strangers.map((f) => `“${f.name}”`).join(", ")})` : "";
    if (extra) note(`The job's files are all here${extra}.`, "warn");
    const what = pending.source === "link" ? LINK_OPEN_LABEL : "open the job file";
    if (await openJob(page, pending.files.map((x) => ({ file: x.file!, name: x.name })), pending.job.parts, target, what)) {
      store.pending = null;
      if (link) linkStage(page, link);
    }
    else store.pending = pending;
    return;
  }
  store.pending = pending;
  store.fileChosenAt = null;
  const list = missing.map((x) => `“${x.name}”${x.sha256 ? ` (SHA-256 ${x.sha256.slice(0, 12)}…)` : ""}`).join(", ");
  const strange = strangers.length ? ` ${strangers.map((f) => `“${f.name}”`).join(", ")} ${strangers.length > 1 ? "are" : "is"} not one of them${pending.source === "link" ? " (a different SHA-256)" : ""}.` : "";
  showBanner(
    pending.source === "link" ? TITLES.linkFiles : TITLES.jobFiles,
    `Still missing: ${list}. Drop ${missing.length > 1 ? "those files" : "that file"} here${strange}`,
    "info",
    true,
  );
  setState("idle");
  updateButtons(page);
}

const baseOf = (path: string) => path.replace(/^.*[\\/]/, "");

/** The job's settings into the form (the defaults for the others); unknown names are said. */
function applyJobSettings(page: Page, settings: JobFile["settings"]): void {
  const clean: Record<string, Value> = {};
  for (const [k, v] of Object.entries(settings)) if (typeof v === "number" || typeof v === "boolean" || typeof v === "string") clean[k] = v;
  const unknown = page.form!.setRaw({ ...DEFAULTS, ...clean });
  if (unknown.length) note(`Settings unknown here were ignored: ${unknown.join(", ")}.`, "warn");
}

/** The sample part as a new job (`target`: the layer, or a notice to show with it). */
export async function openSample(page: Page, target: Target = {}): Promise<void> {
  const s = sampleStl();
  setState("reading");
  page.store.pending = null;
  note("", "none");
  await openJob(page, [{ file: new File([s.bytes as BlobPart], s.name, { type: "model/stl" }) }], undefined, target, "open the sample part");
}

/** What a link's settings must be for each kind of setting (the form checks the ranges). */
const KIND_TYPE: Record<Spec["kind"], { type: string; words: string }> = {
  number: { type: "number", words: "a number" },
  integer: { type: "number", words: "a whole number" },
  bool: { type: "boolean", words: "yes or no (true/false)" },
  enum: { type: "string", words: "one of the choices" },
  order: { type: "string", words: "an order of units (unit0_first, or a list such as 2,0,1)" },
};

/** The link's settings whose type fits their kind; the others named in `ignored`. Unknown
 *  names are kept (the form ignores them and the page says so). */
function linkSettings(page: Page, settings: RawSettings, ignored: string[]): RawSettings {
  const out: Record<string, Value> = {};
  for (const [name, v] of Object.entries(settings)) {
    const spec = page.init!.schema.find((x) => x.name === name);
    const want = spec ? KIND_TYPE[spec.kind] : undefined;
    if (want && typeof v !== want.type) {
      const shown = typeof v === "string" ? JSON.stringify(v.length > 24 ? `${v.slice(0, 24)}…` : v) : String(v);
      ignored.push(`its setting ${name} (${shown} is not ${want.words}: the default is used)`);
      continue;
    }
    out[name] = v;
  }
  return out;
}

/** The job of a link: its parts, or (a link of one model from an older page) one part of its
 *  model, which takes the link's part settings (rotate_z, scale_x, …) as its own. */
function linkJob(state: ShareState, settings: RawSettings): JobFile {
  const part: PartSpec = { file: state.name, ...partKeysOf(settings) };
  if ((part.place_x === undefined) !== (part.place_y === undefined)) (part.place_x === undefined ? (part.place_x = 0) : (part.place_y = 0));
  // unknown names stay (the form names them), the part keys go to the part
  return { settings: jobSettings(settings as SomeSettings) as RawSettings, parts: state.parts ?? [part] };
}

/** A link's stage once its job is sliced: the 3D view and its camera, or the layer view with
 *  the cut line. */
function linkStage(page: Page, state: ShareState): void {
  if (state.mode) page.view3d.setActive(state.mode === "3d");
  if (state.camera) page.view3d.setCamera(state.camera);
  if (state.cut && page.store.slice) setLine(page, state.cut, true);
}

/** The settings of a link that differ from the defaults, in words: "layer height 0.2 mm
 *  (default 0.25)". */
function differing(page: Page, settings: SomeSettings): string[] {
  const out: string[] = [];
  for (const spec of page.init!.schema) {
    const v = settings[spec.name];
    const d = DEFAULTS[spec.name];
    if (v === undefined || v === d || spec.part) continue;
    const unit = spec.unit && typeof v === "number" ? ` ${spec.unit}` : "";
    out.push(`${spec.name.replace(/_/g, " ")} ${String(v)}${unit} (default ${String(d)})`);
  }
  return out;
}

/** Opens the preview link in the URL, if there is one (returns whether there was one that the
 *  page now shows or waits for files of). A link too large or damaged is refused with a
 *  message and the sample part is shown; fields it gets wrong are ignored and named. */
export async function openLink(page: Page): Promise<boolean> {
  let link: SharedLink | null;
  try {
    link = await readLink(location.hash, page.init!.job);
  } catch (e) {
    const why = e instanceof LinkError ? e.message : `it could not be read (${e instanceof Error ? e.message : String(e)})`;
    await openSample(page, { notice: { title: TITLES.link, message: `This preview link is too large or damaged: ${why}. Showing the sample part instead.` } });
    return true;
  }
  if (!link) return false;
  const ignored = [...link.ignored];
  const job = linkJob(link.state, linkSettings(page, link.state.settings, ignored));
  const unknown = page.form!.setRaw({ ...DEFAULTS, ...job.settings });
  job.settings = {};
  const extra = unknown.length
    ? ` The link comes from another version: its settings ${unknown.join(", ")} are unknown here and were ignored, so the slice may differ.`
    : "";
  if (extra) note(extra.trim(), "warn");
  setShowTravel(page, Boolean(link.state.showTravel));
  for (const [k, on] of Object.entries(link.state.overlays ?? {})) setOverlay(k as keyof Overlays, on);
  linkFromNote(differing(page, page.form!.values()));
  const notice: Target["notice"] = ignored.length
    ? { title: TITLES.linkPart, message: `This preview link is partly damaged: ${ignored.join("; ")}.`, tone: "info" }
    : undefined;
  const { layer, view, name, sha256 } = link.state;
  const files = link.state.files ?? [{ name, sha256, bytes: link.model?.length ?? 0 }];
  if (link.models) {
    const given = files.map((f, i) => ({ file: new File([link.models![i] as BlobPart], f.name), name: f.name }));
    const hashes = await Promise.all(given.map((g) => page.pool.hash(g.file)));
    const wrong = files.findIndex((f, i) => !hashes[i].startsWith(f.sha256));
    if (wrong < 0) {
      page.store.pending = null;
      if (await openJob(page, given, job.parts, { layer, view, notice }, LINK_OPEN_LABEL)) linkStage(page, link.state);
      return true;
    }
    link.models = null;
    link.modelError = files.length > 1 ? `its model “${files[wrong].name}” does not match the SHA-256 it carries` : "its model does not match the SHA-256 it carries";
  }
  page.store.pending = pendingOf({ ...job, settings: {} }, link.state);
  showModel(null);
  const at = layer !== undefined ? ` to see layer ${nf.format(layer + 1)}` : "";
  const several = files.length > 1;
  const named = several ? `${files.length} models (${files.map((f) => `“${f.name}”`).join(", ")})` : `the model “${name}” (SHA-256 ${sha256.slice(0, 12)}…)`;
  if (link.modelError) {
    const also = ignored.length ? ` Also ignored: ${ignored.join("; ")}.` : "";
    showBanner(TITLES.link, `This preview link is too large or damaged: ${link.modelError}. Its settings are applied; drop ${several ? "its models" : `“${name}”`} here to see the slice.${also}`);
  } else if (notice) {
    showBanner(notice.title, notice.message, notice.tone, true);
  } else if (several) {
    showBanner(TITLES.linkFiles, `Still missing: ${files.map((f) => `“${f.name}”`).join(", ")}. Drop those files here.`, "info", true);
  }
  note(
    link.modelError
      ? `${several ? "The models" : `The model “${name}” (SHA-256 ${sha256.slice(0, 12)}…)`} could not be taken from the link. Drop ${several ? "those files" : "that file"} here${at} with the link's settings.${extra}`
      : `This preview link is for ${named}, too big to put in the link. Drop ${several ? "those files" : "that file"} here${at} with the link's settings.${extra}`,
    "warn",
  );
  setState("idle");
  updateButtons(page);
  return true;
}

// The page's job kept in the browser (core/jobstore.ts, IndexedDB) so that a reload or a crash
// loses nothing: written a moment after every change of the job (each recorded change, undo
// and redo; the models' bytes once per file, by SHA-256), restored at the next visit (a
// preview link in the address takes precedence) with a notice that offers *Start over*. A
// store that cannot be read is set aside with a word; a job whose models pass the cap is not
// kept, and the page says so. Leaving the page asks first whenever the job on screen is not
// the one kept (a write pending, over the cap, no store). A preview link's job is the link's
// until the visitor's first edit: then the address drops the link and the job is theirs.

import { specOut, type Job } from "../core/job";
import { JOB_CAP_BYTES, JobStore, JobStoreError, jobBytes, jobCapBytes, type StoredJob } from "../core/jobstore";
import type { Remembered } from "../core/remember";
import type { Page } from "../views/page";
import { hidePersistNotice, persistNotice } from "../views/persist";
import { selectPart } from "./job";
import { LINK_OPEN_LABEL, openSample, openStored } from "./open";
import { applyRemembered, holdForLink, saveSoon } from "./remember";

/** Changes settle this long before the job is written. */
const WRITE_MS = 400;

/** Whether the store holds the job on screen: `pending` (a write to come or running), `saved`,
 *  `over` (its models pass the cap: not kept), `unavailable` (no store, or it refused). */
export type PersistState = "idle" | "pending" | "saved" | "over" | "unavailable";

const nf = new Intl.NumberFormat("en-US");
const mb = (n: number) => `${nf.format(Math.round(n / 2 ** 20))} MB`;

let cap = JOB_CAP_BYTES;
let opened: Promise<JobStore | null> | null = null;
let state: PersistState = "idle";
let timer = 0;
/** Bumped by every change: a write that ends on an older one leaves the state pending. */
let version = 0;
let writing = false;
/** The tests' hold: writes wait (the state stays pending) until released. */
let paused = false;
/** The page shows a preview link's job that the visitor has not edited yet. */
let link = false;
/** The job the "too big to keep" notice was shown for (once per job). */
let toldOver: Job | null = null;

const store = (): Promise<JobStore | null> => (opened ??= JobStore.open());

/** The cap of `?jobcap=MB` (tests), read once at start. */
export function initPersist(query: URLSearchParams): void {
  cap = jobCapBytes(query);
}

/** The page shows a preview link (opened, or waiting for its files): nothing is kept until the
 *  visitor's first edit. */
export function holdJobForLink(held: boolean): void {
  link = held;
}

/** The job changed (a change recorded as `label`, an undo, a redo): written soon. On a link's
 *  page the first change of the visitor's makes the job and its settings theirs. */
export function jobChanged(page: Page, label?: string): void {
  if (link) {
    if (label === LINK_OPEN_LABEL) return;
    linkBecomesOwn(page);
  }
  version++;
  state = "pending";
  clearTimeout(timer);
  timer = window.setTimeout(() => void write(page), WRITE_MS);
}

/** The first edit on a link's page: the address drops the link (a reload brings back the
 *  edited job, not the link's), the settings are remembered as the visitor's, and a notice
 *  says so. */
function linkBecomesOwn(page: Page): void {
  link = false;
  holdForLink(false);
  saveSoon(page);
  if (location.hash.length > 1) window.history.replaceState(window.history.state, "", location.pathname + location.search);
  persistNotice(
    "This page was opened from a preview link; with your edit its job and settings are now yours, kept in this browser: a reload brings back your work, not the link's. The address no longer holds the link (Copy preview link makes a new one).",
  );
}

/** The job as the store keeps it (null: no job). */
function storedOf(job: Job): { record: StoredJob; blobs: Map<string, Blob> } {
  const used = new Set(job.parts.map((p) => p.spec.file));
  const models = [...job.models.values()].filter((m) => used.has(m.name));
  const sel = job.parts.findIndex((p) => p.id === job.selected);
  return {
    record: {
      files: models.map((m) => ({ name: m.name, sha256: m.sha256, bytes: m.file.size })),
      parts: job.parts.map((p) => specOut(p.spec)),
      selected: sel < 0 ? null : sel,
    },
    blobs: new Map(models.map((m) => [m.sha256, m.file])),
  };
}

async function write(page: Page): Promise<void> {
  if (paused || writing) return;
  const job = page.store.job;
  // a .gco file viewed is not a job: the job kept stays as it was
  if (!job || job.parts.length === 0) {
    state = "saved";
    return;
  }
  const at = version;
  writing = true;
  try {
    const s = await store();
    if (!s) {
      state = "unavailable";
      return;
    }
    const { record, blobs } = storedOf(job);
    const bytes = jobBytes(record);
    if (bytes > cap) {
      // never a stale job brought back instead: the one kept goes
      await s.clear();
      state = "over";
      if (toldOver !== job) {
        toldOver = job;
        persistNotice(`This job's models are ${mb(bytes)}, more than the ${mb(cap)} the page keeps in the browser: it will not come back after a reload. Save the job file and keep its models to open it again.`, false, "warn");
      }
      return;
    }
    await s.save(record, blobs);
    state = at === version ? "saved" : "pending";
  } catch (e) {
    state = "unavailable";
    persistNotice(`The browser refused to keep the job (${e instanceof Error ? e.message : String(e)}): it will not come back after a reload. Save the job file to keep it.`, false, "warn");
  } finally {
    writing = false;
    if (state === "pending" && at !== version) {
      clearTimeout(timer);
      timer = window.setTimeout(() => void write(page), WRITE_MS);
    }
  }
}

/** Whether leaving now loses work: the job on screen is not the one kept (a write to come,
 *  too big to keep, or no store and something was changed). A link's page not yet edited
 *  loses nothing: the address brings it back. */
export function leavingLoses(page: Page): boolean {
  if (!page.store.job || link) return false;
  if (state === "pending" || state === "over") return true;
  if (state === "unavailable") return page.history.undoLabel !== null || page.history.redoLabel !== null;
  return false;
}

/** A kept job that cannot be used: set aside (forgotten) with a word. */
async function setAside(s: JobStore, why: string): Promise<false> {
  await s.clear().catch(() => {});
  persistNotice(`The job kept from last time could not be read (${why}): it was set aside, and the sample part is shown.`, false, "warn");
  return false;
}

/** At start (no link in the address): the job kept from last time, opened with the remembered
 *  settings and view, and the notice with *Start over*. False when none was kept or it could
 *  not be used (the caller opens the sample). */
export async function restoreJob(page: Page, remembered: Remembered | null): Promise<boolean> {
  const s = await store();
  if (!s) {
    state = "unavailable";
    return false;
  }
  let loaded: Awaited<ReturnType<JobStore["load"]>>;
  try {
    loaded = await s.load(page.init!.job, cap);
  } catch (e) {
    return setAside(s, e instanceof JobStoreError ? e.message : `the browser could not read it: ${e instanceof Error ? e.message : String(e)}`);
  }
  if (!loaded) return false;
  const { job, blobs } = loaded;
  const files = job.files.map((f, i) => new File([blobs[i]], f.name));
  let hashes: string[];
  try {
    hashes = await Promise.all(files.map((f) => page.pool.hash(f)));
  } catch (e) {
    return setAside(s, `its models could not be read: ${e instanceof Error ? e.message : String(e)}`);
  }
  const wrong = job.files.findIndex((f, i) => hashes[i] !== f.sha256);
  if (wrong >= 0) return setAside(s, `the bytes of “${job.files[wrong].name}” do not match their SHA-256`);
  if (remembered) applyRemembered(page, remembered);
  const ok = await openStored(page, files.map((file, i) => ({ file, name: job.files[i].name })), job.parts, { layer: remembered?.view.layer ?? undefined });
  if (!ok) {
    // the core refused it (its message is shown): the sample, with the defaults
    page.form!.set(page.init!.defaults);
    return setAside(s, "the core refused it, see the message above");
  }
  const now = page.store.job;
  if (job.selected !== null && now) selectPart(page, now.parts[job.selected]?.id ?? null);
  persistNotice("Your job from last time was restored.", true);
  return true;
}

/** *Start over*: the job kept is forgotten, the settings go back to the defaults, and the
 *  sample part is opened (one change: Undo brings the job back). */
export async function startOver(page: Page): Promise<void> {
  hidePersistNotice();
  clearTimeout(timer);
  const s = await store();
  await s?.clear().catch(() => {});
  if (!page.form || !page.init) return;
  page.form.set(page.init.defaults);
  saveSoon(page);
  await openSample(page);
}

/** The tests' view of the store: its state, the cap, and a hold on writes. */
export function persistStatus(): { state: PersistState; cap: number; link: boolean } {
  return { state, cap, link };
}

export function pausePersist(page: Page, on: boolean): void {
  paused = on;
  if (!on && state === "pending") {
    clearTimeout(timer);
    timer = window.setTimeout(() => void write(page), WRITE_MS);
  }
}

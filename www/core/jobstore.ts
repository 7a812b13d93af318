// The current build job kept in the browser (IndexedDB), so that it survives a reload and a
// crash: its parts (as a job file writes them), its files (name, SHA-256, size) and the part
// selected, and each model's bytes once, keyed by its SHA-256 (an edit stores no bytes; a file
// no part uses any more is deleted). The settings and the view are the page's remembered ones
// (local storage, remember.ts). What is read back is checked like a job file from outside:
// every field's type, range and bound (a damaged store is refused whole with the reason); the
// flow checks each model's bytes against its SHA-256, and the core checks the job again when
// it lays it out. No DOM.

import { fitsPart, partNumber } from "./job";
import type { JobSchema, PartSpec } from "./protocol";

/** Most bytes of models the store keeps (a job beyond it is not kept; the page says so). */
export const JOB_CAP_BYTES = 500 * 2 ** 20;
const DB_NAME = "dropslice.job";
const DB_VERSION = 1;
const JOBS = "job";
const MODELS = "models";
const CURRENT = "current";
/** The record's shape (a new shape gets a new number; an old one is damaged, not misread). */
const RECORD_VERSION = 1;
const NAME_MAX = 255;
const ITEM_MAX = 1_000_000;

/** `?jobcap=MB` (the tests' tuning): a lower cap than [[JOB_CAP_BYTES]] (0: nothing is kept). */
export function jobCapBytes(query: URLSearchParams): number {
  const raw = query.get("jobcap");
  const mb = raw === null || raw.trim() === "" ? NaN : Number(raw);
  return Number.isFinite(mb) && mb >= 0 ? Math.min(JOB_CAP_BYTES, Math.floor(mb * 2 ** 20)) : JOB_CAP_BYTES;
}

export interface StoredFile {
  /** The file's name in the job (the parts name it). */
  name: string;
  /** 64 hexadecimal digits, lower case: the key of its bytes. */
  sha256: string;
  bytes: number;
}

/** The job as the store keeps it. */
export interface StoredJob {
  files: StoredFile[];
  parts: PartSpec[];
  /** The index of the part selected (null: none). */
  selected: number | null;
}

/** A store that holds something other than a job this page wrote (damaged, or changed). */
export class JobStoreError extends Error {}

const isObject = (v: unknown): v is Record<string, unknown> => typeof v === "object" && v !== null && !Array.isArray(v);
const nf = new Intl.NumberFormat("en-US");
const mb = (n: number) => `${nf.format(Math.round(n / 2 ** 20))} MB`;

/** Bytes of models of `job`. */
export const jobBytes = (job: StoredJob): number => job.files.reduce((n, f) => n + f.bytes, 0);

/**
 * `raw` as a stored job, or a [[JobStoreError]] naming what is wrong: at most `limits.max_parts`
 * files and parts, file names of 1 … 255 characters and distinct, SHA-256 of 64 hex digits,
 * sizes whole and adding up to at most `cap`, every part naming a file, every number of a
 * part finite and in the core's range (its `job_schema`), nothing else.
 */
export function checkStoredJob(raw: unknown, limits: JobSchema, cap = JOB_CAP_BYTES): StoredJob {
  const bad = (why: string) => new JobStoreError(why);
  if (!isObject(raw) || raw.version !== RECORD_VERSION) throw bad("it is not a job of this page");
  if (!Array.isArray(raw.files) || raw.files.length === 0 || raw.files.length > limits.max_parts) throw bad(`its files are not a list of 1 … ${limits.max_parts}`);
  const files: StoredFile[] = [];
  let total = 0;
  for (const [i, f] of raw.files.entries()) {
    const at = `its file ${i + 1}`;
    if (!isObject(f) || typeof f.name !== "string" || f.name.length === 0 || f.name.length > NAME_MAX) throw bad(`${at} has no name of 1 … ${NAME_MAX} characters`);
    if (files.some((g) => g.name === f.name)) throw bad(`${at} repeats the name of another`);
    if (typeof f.sha256 !== "string" || !/^[0-9a-f]{64}$/.test(f.sha256)) throw bad(`${at} has no SHA-256`);
    if (typeof f.bytes !== "number" || !Number.isInteger(f.bytes) || f.bytes < 0) throw bad(`${at} has no size`);
    total += f.bytes;
    if (total > cap) throw bad(`its models are more than ${mb(cap)}`);
    files.push({ name: f.name, sha256: f.sha256, bytes: f.bytes });
  }
  if (!Array.isArray(raw.parts) || raw.parts.length === 0 || raw.parts.length > limits.max_parts) throw bad(`its parts are not a list of 1 … ${limits.max_parts}`);
  const parts = raw.parts.map((p, i) => checkPart(p, i, files, limits));
  const s = raw.selected;
  if (s !== null && !(typeof s === "number" && Number.isInteger(s) && s >= 0 && s < parts.length)) throw bad("its selected part is not one of its parts");
  return { files, parts, selected: s };
}

function checkPart(p: unknown, i: number, files: StoredFile[], limits: JobSchema): PartSpec {
  const at = `its part ${i + 1}`;
  if (!isObject(p) || typeof p.file !== "string" || !files.some((f) => f.name === p.file)) throw new JobStoreError(`${at} names none of its files`);
  const out: PartSpec = { file: p.file };
  for (const [k, v] of Object.entries(p)) {
    if (k === "file") continue;
    if (k === "name") {
      if (typeof v !== "string" || v.length > NAME_MAX) throw new JobStoreError(`${at}'s name is not a text of at most ${NAME_MAX} characters`);
      out.name = v;
    } else if (k === "item") {
      if (typeof v !== "number" || !Number.isInteger(v) || v < 0 || v > ITEM_MAX) throw new JobStoreError(`${at}'s item is not a whole number in 0 … ${nf.format(ITEM_MAX)}`);
      out.item = v;
    } else {
      const spec = partNumber(limits, k);
      if (!spec) throw new JobStoreError(`${at} holds ${/^[a-z_]{1,40}$/.test(k) ? k : "an unknown key"}, not a part's setting`);
      if (typeof v !== "number" || !fitsPart(spec, v)) throw new JobStoreError(`${at}'s ${k} is not a number in the core's range`);
      (out as unknown as Record<string, number>)[k] = v;
    }
  }
  if ((out.place_x === undefined) !== (out.place_y === undefined)) throw new JobStoreError(`${at} has one coordinate of its place`);
  return out;
}

/** A request's result (or its error) as a promise. */
function done<T>(r: IDBRequest<T>): Promise<T> {
  return new Promise((ok, fail) => {
    r.onsuccess = () => ok(r.result);
    r.onerror = () => fail(r.error ?? new Error("IndexedDB request failed"));
  });
}

/** A transaction's end as a promise. */
function finished(tx: IDBTransaction): Promise<void> {
  return new Promise((ok, fail) => {
    tx.oncomplete = () => ok();
    tx.onerror = () => fail(tx.error ?? new Error("IndexedDB transaction failed"));
    tx.onabort = () => fail(tx.error ?? new Error("IndexedDB transaction aborted"));
  });
}

/** The store of the page's job (one per page). */
export class JobStore {
  private constructor(private readonly db: IDBDatabase) {}

  /** The browser's store (null: IndexedDB is missing or refused, e.g. blocked storage). */
  static async open(): Promise<JobStore | null> {
    try {
      if (typeof indexedDB === "undefined") return null;
      const req = indexedDB.open(DB_NAME, DB_VERSION);
      req.onupgradeneeded = () => {
        const db = req.result;
        if (!db.objectStoreNames.contains(JOBS)) db.createObjectStore(JOBS);
        if (!db.objectStoreNames.contains(MODELS)) db.createObjectStore(MODELS);
      };
      return new JobStore(await done(req));
    } catch {
      return null;
    }
  }

  /** The stored job and its models' bytes in the order of its files (null: none stored).
   *  Throws a [[JobStoreError]] when what is stored is not a job or its bytes are missing. */
  async load(limits: JobSchema, cap = JOB_CAP_BYTES): Promise<{ job: StoredJob; blobs: Blob[] } | null> {
    const raw = await done(this.db.transaction(JOBS, "readonly").objectStore(JOBS).get(CURRENT));
    if (raw === undefined) return null;
    const job = checkStoredJob(raw, limits, cap);
    const models = this.db.transaction(MODELS, "readonly").objectStore(MODELS);
    const blobs = await Promise.all(job.files.map((f) => done(models.get(f.sha256))));
    job.files.forEach((f, i) => {
      const b: unknown = blobs[i];
      if (!(b instanceof Blob)) throw new JobStoreError(`the bytes of “${f.name}” are missing`);
      if (b.size !== f.bytes) throw new JobStoreError(`“${f.name}” has ${nf.format(b.size)} bytes, not ${nf.format(f.bytes)}`);
    });
    return { job, blobs: blobs as Blob[] };
  }

  /** Keeps `job` (replacing the one kept): the bytes of its files not kept yet (`blobs`, by
   *  SHA-256) are added, those of files it no longer has deleted, in one transaction. */
  async save(job: StoredJob, blobs: ReadonlyMap<string, Blob>): Promise<void> {
    const tx = this.db.transaction([JOBS, MODELS], "readwrite");
    const end = finished(tx);
    const models = tx.objectStore(MODELS);
    const want = new Set(job.files.map((f) => f.sha256));
    const keys = models.getAllKeys();
    keys.onsuccess = () => {
      const have = new Set(keys.result.map(String));
      for (const sha of want) {
        const b = blobs.get(sha);
        if (!have.has(sha) && b) models.put(b, sha);
      }
      for (const sha of have) if (!want.has(sha)) models.delete(sha);
      tx.objectStore(JOBS).put({ version: RECORD_VERSION, ...job }, CURRENT);
    };
    await end;
  }

  /** Forgets the job and every model's bytes. */
  async clear(): Promise<void> {
    const tx = this.db.transaction([JOBS, MODELS], "readwrite");
    const end = finished(tx);
    tx.objectStore(JOBS).clear();
    tx.objectStore(MODELS).clear();
    await end;
  }
}

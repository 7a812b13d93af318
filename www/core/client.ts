// The worker pool: one worker per core (hardwareConcurrency, 1 … 8), each with its own wasm
// instance. The first worker is the job worker: it holds the job's files (`Models`: added as
// Files, read and imported there), answers layout, display meshes and lay-flat, and prepares a
// slice (`Session.from_models`: place, merge, weld, checks, repair); the other workers hold no
// files: they take the job worker's prepared job as bytes (`adopt_job`), so nothing is read or
// prepared twice (see [[openAll]]); a slice starts them on the job worker's draft before the
// job is made (see [[Pool.sliceDrafted]]). The pool
// remembers which Files the job worker holds and adds them again to a fresh worker (after a
// cancel or a crash), so the page only ever says which files the job has. Each worker, as soon
// as it holds the model, takes units of consecutive layers from a shared counter (two units in
// flight, so it never waits for the page between units). Layers come back in batches ("layers" replies,
// buffers transferred) and are stored by index, so the page sees them in layer order however
// the workers finish; a unit's result carries its G-code as one Blob. Cancel terminates every
// worker at once, rejects what was pending and starts fresh workers. The core's module is
// compiled once, here ([[compiledCore]]), and posted to every worker as its first message: no
// worker fetches or compiles it, and the engine shares its compiled code among them.

import type {
  GcodeParseResult,
  JobFile,
  Layout,
  ModelInfo,
  ModuleMessage,
  LayerData,
  OpenResult,
  Reply,
  RequestData,
  RequestKind,
  ResultOf,
  SliceFigures,
  SliceUnit,
  Summary,
} from "./protocol";
import { checkInit, type PageInit } from "./settings";
import { type Unit, Speculation, UnitCounter, unitCounter } from "./layerwork";
import { StageClock, publish } from "./stages";

/** The page's side of the per-stage profile (core/stages.ts). */
const clock = publish(new StageClock());

/** The core's module, compiled once per page (streaming from its URL, so that the HTTP cache
 *  and the engine's code cache apply on the next visit) and shared by every worker. A failure
 *  is an error of kind "crash" naming the cause; the next worker started tries again. */
let compiled: Promise<WebAssembly.Module> | null = null;

export function compiledCore(): Promise<WebAssembly.Module> {
  if (!compiled) {
    const url = new URL("./dropslice_bg.wasm", import.meta.url);
    compiled = compileCore(url);
    compiled.catch(() => (compiled = null));
  }
  return compiled;
}

async function compileCore(url: URL): Promise<WebAssembly.Module> {
  performance.mark("dropslice: compile start");
  let response: Response;
  try {
    response = await fetch(url);
  } catch (e) {
    throw new SliceError("crash", `could not load the slicer (${url.pathname}): ${String(e)}. Check the connection and reload the page.`);
  }
  if (!response.ok) {
    throw new SliceError("crash", `could not load the slicer (${url.pathname}): the server answered ${response.status}. Reload the page; if it stays, the site is incomplete.`);
  }
  try {
    // compileStreaming needs the type application/wasm; a server that sends another type
    // gets the plain compile of the bytes (no streaming, no code cache)
    const wasmType = (response.headers.get("content-type") ?? "").split(";")[0].trim().toLowerCase() === "application/wasm";
    const module = wasmType ? await WebAssembly.compileStreaming(response) : await WebAssembly.compile(await response.arrayBuffer());
    performance.measure("dropslice: compile", "dropslice: compile start");
    return module;
  } catch (e) {
    throw new SliceError("crash", `the slicer's module does not load in this browser (${String(e)}). Reload the page, or use a current browser.`);
  }
}

/** An error from a worker: the core's `{kind, message, setting?}` or the page's "crash". */
export class SliceError extends Error {
  constructor(
    readonly kind: string,
    message: string,
    readonly setting?: string,
  ) {
    super(message);
  }
}

export class Cancelled extends Error {
  constructor() {
    super("cancelled");
  }
}

interface Pending {
  resolve: (v: unknown) => void;
  reject: (e: Error) => void;
  progress?: (layer: LayerData) => void;
  /** `open_job`'s drafts (protocol.ts, the "draft" reply). */
  draft?: (drafts: Uint8Array[]) => void;
}

/** Workers started so far (the tests' hook: a cancel replaces which ones). */
let started = 0;

class WorkerHandle {
  private worker: Worker;

  /** Asks the worker, once, to compile the layer path while it waits for a job (the engine
   *  compiles a function on its first call: else the job's first layer does it). */
  warmUp(): void {
    if (this.warmed || this.broken) return;
    this.warmed = true;
    this.call("warm", {}).catch(() => {});
  }

  /** Settles once the module was posted (the worker's first message): requests go after it. */
  private started: Promise<void>;
  private pending = new Map<number, Pending>();
  private nextId = 1;
  /** A crashed wasm instance cannot be trusted again. */
  broken = false;
  /** Whether the worker holds the current model. */
  hasModel = false;
  /** Whether it was asked to compile the layer path ahead of a job ([[warmUp]]). */
  private warmed = false;
  /** The job's files this worker's `Models` holds, by job name (the job worker's). */
  readonly models = new Map<string, File>();
  /** Why the worker was terminated: a request made after that (one that awaited something
   *  first) is refused with it at once, never left without an answer. */
  private ended: Error | null = null;

  constructor() {
    started++;
    this.worker = new Worker(new URL("./worker.js", import.meta.url), { type: "module", name: "dropslice" });
    this.worker.onmessage = (ev: MessageEvent<Reply>) => this.receive(ev.data);
    this.worker.onerror = (ev: ErrorEvent) => {
      ev.preventDefault();
      this.broken = true;
      this.failAll(new SliceError("crash", `the slicer worker failed: ${ev.message || "could not start"}`));
    };
    this.started = compiledCore().then((module) => {
      const first: ModuleMessage = { kind: "module", module };
      this.worker.postMessage(first);
    });
    this.started.catch(() => (this.broken = true)); // each request is rejected with the reason
  }

  get load(): number {
    return this.pending.size;
  }

  /** Sends request `kind` with its data (checked against protocol.ts `Calls`) and resolves
   *  with its typed result. */
  call<K extends RequestKind>(
    kind: K,
    data: RequestData<K>,
    progress?: (layer: LayerData) => void,
    transfer: Transferable[] = [],
    draft?: (drafts: Uint8Array[]) => void,
  ): Promise<ResultOf<K>> {
    const id = this.nextId++;
    // one member of protocol.ts `Request`, checked by the signature (no cast)
    const message: { id: number; kind: K; data: RequestData<K> } = { id, kind, data };
    return new Promise<ResultOf<K>>((resolve, reject) => {
      if (this.ended) return reject(this.ended);
      this.pending.set(id, { resolve: resolve as (v: unknown) => void, reject, progress, draft });
      // after the module (a `then` of the one promise runs in the order they were added)
      this.started.then(
        () => this.worker.postMessage(message, transfer),
        (e: unknown) => {
          if (this.pending.delete(id)) reject(e instanceof Error ? e : new SliceError("crash", String(e)));
        },
      );
    });
  }

  private receive(reply: Reply): void {
    const p = this.pending.get(reply.id);
    if (!p) return;
    if (reply.kind === "progress") {
      p.progress?.(reply.data);
      return;
    }
    if (reply.kind === "layers") {
      for (const l of reply.data) p.progress?.(l);
      return;
    }
    if (reply.kind === "draft") {
      p.draft?.(reply.data.drafts);
      return;
    }
    this.pending.delete(reply.id);
    if (reply.kind === "result") p.resolve(reply.data);
    else {
      if (reply.data.kind === "crash") this.broken = true;
      p.reject(new SliceError(reply.data.kind, reply.data.message, reply.data.setting));
    }
  }

  private failAll(e: Error): void {
    const all = [...this.pending.values()];
    this.pending.clear();
    for (const p of all) p.reject(e);
  }

  terminate(reason: Error): void {
    this.ended = reason;
    this.worker.terminate();
    this.failAll(reason);
  }
}

/** One worker per core, 1 … [[MAX_WORKERS]]: every worker prepares the job at the same time
 *  (see [[openAll]]), so all of them slice from the start. */
export function defaultPoolSize(): number {
  const n = navigator.hardwareConcurrency || 1;
  return Math.max(1, Math.min(n, MAX_WORKERS));
}

export interface SliceCallbacks {
  opened(result: OpenResult): void;
  layer(layer: LayerData): void;
  /** A run of layers is complete: its G-code and summary (after all its layers). */
  unit(unit: SliceUnit): void;
}

/** A file of the job: its name in the job (the key in `Models`) and the File. */
export interface JobFileRef {
  name: string;
  file: File;
}

/** Makes worker `h` hold exactly `files` (adds the ones it lacks or holds as another File,
 *  removes the others). A worker answers its requests in order, so a file whose import was
 *  sent already counts as held. */
async function syncModels(h: WorkerHandle, files: JobFileRef[]): Promise<void> {
  const wanted = new Map(files.map((f) => [f.name, f.file]));
  const gone = [...h.models.keys()].filter((n) => !wanted.has(n));
  for (const n of gone) h.models.delete(n);
  // both requests at once: the worker answers them in order
  const removed = gone.length ? h.call("models_remove", { names: gone }) : null;
  removed?.catch(() => {}); // awaited below
  const missing = files.filter((f) => h.models.get(f.name) !== f.file);
  if (missing.length) await addTo(h, missing, null);
  await removed;
}

/** Adds `files` to `h`'s Models. Their SHA-256 comes from `hasher`: another worker hashes
 *  while `h` reads and imports (in `h` the hash would wait for the import: its thread is busy);
 *  `h` itself hashes after reading; `null`: no hash. The files count as held from the request
 *  on (see [[syncModels]]); on a refusal the names are forgotten (the worker may have replaced
 *  some of them before refusing one). */
async function addTo(h: WorkerHandle, files: JobFileRef[], hasher: WorkerHandle | null): Promise<ResultOf<"models_add">> {
  for (const f of files) h.models.set(f.name, f.file);
  try {
    const aside = hasher && hasher !== h ? Promise.all(files.map((f) => hasher.call("hash", { file: f.file }))) : null;
    aside?.catch(() => {}); // awaited below; a refusal of the import must not leave it unhandled
    const r = await h.call("models_add", { files, hash: hasher === h });
    const sha256 = aside ? await aside : r.sha256;
    return { infos: r.infos, sha256 };
  } catch (e) {
    for (const f of files) if (h.models.get(f.name) === f.file) h.models.delete(f.name);
    throw e;
  }
}

/** Makes `h` hold `files` and opens `job` there (`share`: copies of the prepared job for
 *  other workers, see [[openAll]]): all its requests posted at once (it answers them in order;
 *  a round trip through the page's busy thread between them cost a worker tens of ms). A
 *  refusal of the files is reported before the job's. */
async function syncThenOpen(
  h: WorkerHandle,
  files: JobFileRef[],
  job: JobFile,
  share: number,
  draft?: (drafts: Uint8Array[]) => void,
): Promise<ResultOf<"open_job">> {
  const synced = syncModels(h, files);
  const opened = h.call("open_job", { job, share, draft: draft !== undefined }, undefined, [], draft);
  opened.catch(() => {}); // awaited below, after the files
  await synced;
  return opened;
}

/** Opens a job in every worker: the job worker prepares it from the job's files (imported
 *  when they were added) and hands the prepared job as bytes to the others, which take it
 *  without reading a file or preparing anything (`adopt_job`; on 2 cores every worker
 *  preparing the job itself made the job worker's preparation slower by what the other's cost,
 *  and computed everything twice). `ready(h, r)` runs for each worker once it holds the job,
 *  for the job worker first. If the job worker refuses the job, no worker opens it (each keeps
 *  its previous model, the others no longer answer for it); the job worker's refusal is the one
 *  reported. */
async function openAll(
  handles: WorkerHandle[],
  files: JobFileRef[],
  job: JobFile,
  ready: (h: WorkerHandle, r: OpenResult) => Promise<void>,
): Promise<OpenResult> {
  const [first, ...others] = handles;
  // The others answer nothing of the slice shown from now on: a request queued behind their
  // opening would be answered by the new job before the page knows of it. The job worker
  // answers the page's requests in order: after its answer to `open_job` (the page has the
  // new job then), or from its previous model if it refuses the job.
  for (const h of others) {
    h.hasModel = false;
    h.warmUp();
  }
  const { prepared = [], ...r } = await syncThenOpen(first, files, job, others.length);
  first.hasModel = true;
  if (prepared.length < others.length) throw new SliceError("internal", "the job worker handed over too few copies of the job");
  // the others' requests go out before the job worker's first units
  const adopted = others.map(async (h, k) => {
    const o = await h.call("adopt_job", { prepared: prepared[k] }, undefined, [prepared[k].buffer]);
    h.hasModel = true;
    return { h, o };
  });
  for (const p of adopted) p.catch(() => {}); // awaited below
  const work = [ready(first, r)];
  for (const p of adopted) work.push(p.then(({ h, o }) => ready(h, o)));
  await Promise.all(work);
  return r;
}

/** Units in flight per worker: the worker starts the next one while the page answers. */
const UNITS_IN_FLIGHT = 2;

/** Never more workers than this, whatever is asked: each holds its own copy of the mesh. */
export const MAX_WORKERS = 8;

export class Pool {
  private handles: WorkerHandle[] = [];
  readonly size: number;

  /** Requests the job worker has not answered yet (the tests' hook). */
  get jobWorkerLoad(): number {
    return this.handles[0].load;
  }

  /** Workers started so far by every pool (cancels and crashes replace them). */
  static get started(): number {
    return started;
  }

  /** `size` workers, brought within 1 … [[MAX_WORKERS]] (the default when not a number). */
  constructor(size = defaultPoolSize()) {
    this.size = Number.isFinite(size) ? Math.max(1, Math.min(MAX_WORKERS, Math.round(size))) : defaultPoolSize();
    this.respawn();
  }

  private respawn(): void {
    this.handles = Array.from({ length: this.size }, () => new WorkerHandle());
  }

  /** Replaces crashed workers; returns true if any was replaced (their models are gone). */
  private heal(): boolean {
    let healed = false;
    this.handles = this.handles.map((h) => {
      if (!h.broken) return h;
      healed = true;
      h.terminate(new SliceError("crash", "worker replaced"));
      return new WorkerHandle();
    });
    return healed;
  }

  /** Stops the job worker at once (a long call of its own, such as orient: it cannot be
   *  interrupted) and starts a fresh one in its place; what it had pending rejects with
   *  [[Cancelled]]. The fresh worker gets the job's files again with its next request (see
   *  [[onJobWorker]]); the other workers go on as they were. Returns whether a worker still
   *  holds the slice's model (with one worker, none: the caller opens it again). */
  restartJobWorker(): boolean {
    const old = this.handles[0];
    this.handles = [new WorkerHandle(), ...this.handles.slice(1)];
    old.terminate(new Cancelled());
    return this.handles.some((h) => h.hasModel && !h.broken);
  }

  /** Stops everything at once and starts fresh workers. */
  cancel(): void {
    const old = this.handles;
    this.opening = null;
    this.respawn();
    for (const h of old) h.terminate(new Cancelled());
  }

  private async guarded<T>(run: () => Promise<T>): Promise<T> {
    try {
      return await run();
    } catch (e) {
      if (e instanceof SliceError && e.kind === "crash") {
        // A crashed instance may be half-way through anything: start over with fresh workers.
        this.cancel();
      }
      throw e;
    }
  }

  /** The core's version, schema and defaults, checked against the page's settings table
 *  (core/settings.ts `checkInit`). */
  init(): Promise<PageInit> {
    this.heal();
    return this.guarded(async () => checkInit(await this.handles[0].call("init", null)));
  }

  /** Slices a job of `files`: opens it (see [[openAll]]) and streams all layers through
   *  `cb.layer`. With more than one worker and no analysis, the others slice from the job
   *  worker's draft while it prepares the job ([[sliceDrafted]]). */
  slice(files: JobFileRef[], job: JobFile, cb: SliceCallbacks, analyse = false): Promise<OpenResult> {
    this.heal();
    return this.guarded(async () => {
      this.opening = null;
      const handles = this.handles;
      if (!analyse && handles.length > 1) return this.sliceDrafted(handles, files, job, cb);
      let nextUnit: () => Unit | null = () => null;
      return openAll(handles, files, job, async (h, r) => {
        if (h === handles[0]) {
          nextUnit = unitCounter(r.layers, handles.length);
          cb.opened(r);
        }
        const layer = (l: LayerData) => clock.time("page: layer arrived (store, draw)", () => cb.layer(l));
        const unit = (u: SliceUnit) => clock.time("page: unit arrived (figures)", () => cb.unit(u));
        await this.units(h, nextUnit, { analyse }, layer, unit);
      });
    });
  }

  /** [[slice]] with the preparation off the critical path: the job worker hands out a draft
   *  of the job as soon as its parts are merged (`open_job` with `draft`), and every other
   *  worker takes it (`adopt_draft`) and slices units of layers while the
   *  job worker finds the shells, turns them, repairs and checks the job. What they send is
   *  held ([[Speculation]]) until the job worker confirms the job is the draft's
   *  (`confirm_job`, a few kB); if it is not (a repair changed the mesh) or the job is
   *  refused, those workers are replaced, their units given back, and the fresh ones take the
   *  prepared job as [[openAll]] does. */
  private async sliceDrafted(handles: WorkerHandle[], files: JobFileRef[], job: JobFile, cb: SliceCallbacks): Promise<OpenResult> {
    const [first, ...others] = handles;
    const layer = (l: LayerData) => clock.time("page: layer arrived (store, draw)", () => cb.layer(l));
    const unit = (u: SliceUnit) => clock.time("page: unit arrived (figures)", () => cb.unit(u));
    // the others answer nothing of the slice shown from now on (see [[openAll]])
    for (const h of others) {
      h.hasModel = false;
      h.warmUp();
    }
    let counter: UnitCounter | null = null;
    const counterOf = (layers: number): UnitCounter => (counter ??= new UnitCounter(layers, handles.length));
    const drafted = (): UnitCounter | null => counter;
    const drafts: (Speculation<WorkerHandle> | null)[] = others.map(() => null);
    const onDraft = (copies: Uint8Array[]): void => {
      others.forEach((h, k) => {
        const copy = copies[k];
        if (drafts[k] || !copy) return;
        const sp = new Speculation(h);
        drafts[k] = sp;
        sp.lanes = (async () => {
          const { layers } = await h.call("adopt_draft", { prepared: copy }, undefined, [copy.buffer]);
          if (sp.state === "dropped") return;
          const c = counterOf(layers);
          if (c.layers !== layers) throw new SliceError("internal", "two drafts of one job differ in their layers");
          const next = (): Unit | null => {
            if (sp.state === "dropped") return null;
            const u = c.next();
            if (u && sp.state === "draft") sp.taken.push(u);
            return u;
          };
          await this.units(h, next, { analyse: false }, (l) => sp.pass(() => layer(l)), (u) => sp.pass(() => unit(u)));
        })();
        sp.lanes.catch(() => {}); // awaited once confirmed
      });
    };
    /** Drops a draft's worker: a fresh worker takes its place (none if it was replaced
     *  meanwhile, by a cancel or a crash). */
    const replace = (sp: Speculation<WorkerHandle>): WorkerHandle | null => {
      sp.drop(drafted());
      const i = this.handles.indexOf(sp.h);
      if (i < 0) return null;
      const fresh = new WorkerHandle();
      this.handles[i] = fresh;
      sp.h.terminate(new SliceError("internal", "the job's draft did not stand"));
      return fresh;
    };
    let r: ResultOf<"open_job">;
    try {
      r = await syncThenOpen(first, files, job, others.length, onDraft);
    } catch (e) {
      for (const sp of drafts) if (sp) replace(sp);
      throw e;
    }
    first.hasModel = true;
    const { prepared, confirm, ...opened } = r;
    if ((drafted()?.layers ?? opened.layers) !== opened.layers) {
      for (const sp of drafts) if (sp) replace(sp);
      throw new SliceError("internal", "the job's draft and the job differ in their layers");
    }
    const c = counterOf(opened.layers);
    cb.opened(opened);
    const work: Promise<void>[] = [this.units(first, () => c.next(), { analyse: false }, layer, unit)];
    others.forEach((h, k) => {
      const sp = drafts[k];
      const table = confirm?.[k];
      if (sp && table) {
        work.push(
          (async () => {
            await h.call("confirm_job", { table }, undefined, [table.buffer]);
            h.hasModel = true;
            sp.confirm();
            await sp.lanes;
          })(),
        );
        return;
      }
      const worker = sp ? replace(sp) : h;
      const bytes = prepared?.[k];
      work.push(
        (async () => {
          if (!worker) throw new Cancelled();
          if (!bytes) throw new SliceError("internal", "the job worker handed over too few copies of the job");
          await worker.call("adopt_job", { prepared: bytes }, undefined, [bytes.buffer]);
          worker.hasModel = true;
          await this.units(worker, () => c.next(), { analyse: false }, layer, unit);
        })(),
      );
    });
    for (const w of work) w.catch(() => {}); // awaited below
    await Promise.all(work);
    return opened;
  }

  /** Runs units from `nextUnit` on one worker, [[UNITS_IN_FLIGHT]] at a time, until it has none. */
  private async units(
    h: WorkerHandle,
    nextUnit: () => Unit | null,
    options: { analyse: boolean; gcode?: boolean },
    layer: (l: LayerData) => void,
    unit?: (u: SliceUnit) => void,
  ): Promise<void> {
    const lane = async () => {
      for (let u = nextUnit(); u; u = nextUnit()) {
        const done: SliceUnit = await h.call("slice", { ...u, ...options }, layer);
        unit?.(done);
      }
    };
    await Promise.all(Array.from({ length: UNITS_IN_FLIGHT }, lane));
  }

  /** Opens a job in every worker without slicing it (to browse a finished slice again
   *  after the workers were replaced by a cancel or a crash). */
  open(files: JobFileRef[], job: JobFile): Promise<void> {
    this.heal();
    const opening = this.guarded(async () => {
      await openAll(this.handles, files, job, async () => {});
    });
    this.opening = opening.catch(() => {});
    return opening;
  }

  /** Set while open() is under way: requests that need the model wait for it. */
  private opening: Promise<void> | null = null;

  private async pick(): Promise<WorkerHandle> {
    if (this.opening) await this.opening;
    const ready = this.handles.filter((h) => h.hasModel && !h.broken);
    if (ready.length === 0) throw new SliceError("internal", "no worker holds the model any more; slice again");
    return ready.reduce((a, b) => (b.load < a.load ? b : a));
  }

  /** Re-plans one layer of the current model (for layers evicted from the page's cache). */
  preview(index: number, analyse = false): Promise<LayerData> {
    return this.guarded(async () => (await this.pick()).call("preview", { index, analyse }));
  }

  /** The G-code header: with the merged summary of a finished slice, or placeholders. */
  header(summary: Summary | null): Promise<string> {
    return this.guarded(async () => (await this.pick()).call("header", { summary }));
  }

  footer(summary: Summary): Promise<string> {
    return this.guarded(async () => (await this.pick()).call("footer", { summary }));
  }

  /** The core's figures of the summaries `parts` (merged by the core, in any order). */
  figures(parts: Summary[]): Promise<SliceFigures> {
    return this.guarded(async () => (await this.pick()).call("figures", { parts }));
  }

  /** Adds files to the job worker (read and imported there): their info and SHA-256, in
   *  order. A name it holds already is replaced. Nothing else of the job changes. */
  addModels(files: JobFileRef[]): Promise<{ infos: ModelInfo[]; sha256: string[] }> {
    this.heal();
    return this.guarded(() => addTo(this.handles[0], files, this.handles[1] ?? this.handles[0]));
  }

  /** Where every instance of `job` goes (the core's arrangement; it checks the whole job). */
  layout(files: JobFileRef[], job: JobFile): Promise<Layout> {
    return this.onJobWorker(files, (h) => h.call("layout", { job }));
  }

  /** A decimated mesh of a file (or a 3MF item) for the 3D view. */
  displayMesh(files: JobFileRef[], name: string, item: number | undefined, max: number): Promise<Float32Array> {
    return this.onJobWorker(files, (h) => h.call("display_mesh", { name, item, max }));
  }

  /** The rotation (x, then y) that puts a file's largest flat face down. */
  layFlat(files: JobFileRef[], name: string, item: number | undefined): Promise<{ rotate_x: number; rotate_y: number }> {
    return this.onJobWorker(files, (h) => h.call("lay_flat", { name, item }));
  }

  /** The candidate orientations of `job.parts[part]`, best first. */
  orient(files: JobFileRef[], job: JobFile, part: number): Promise<ResultOf<"orient">> {
    return this.onJobWorker(files, (h) => h.call("orient", { job, part }));
  }

  /** Runs `run` on the job worker once it holds exactly `files`. */
  private onJobWorker<T>(files: JobFileRef[], run: (h: WorkerHandle) => Promise<T>): Promise<T> {
    this.heal();
    return this.guarded(async () => {
      const h = this.handles[0];
      await syncModels(h, files);
      return run(h);
    });
  }

  /** SHA-256 of a file, hex, computed in a worker (the page never reads the file). */
  hash(file: Blob): Promise<string> {
    this.heal();
    return this.guarded(() => this.handles[0].call("hash", { file }));
  }

  parseGcode(file: Blob, layer: (l: LayerData) => void): Promise<GcodeParseResult> {
    this.heal();
    return this.guarded(() => this.handles[0].call("parse_gcode", { file }, layer));
  }

  /** Re-plans and analyses layers [0, n) of the current model (no G-code), spread over the
   *  workers holding it: for the void overlay after a slice made without analysis. */
  analyse(n: number, layer: (l: LayerData) => void, unit: (u: SliceUnit) => void): Promise<void> {
    return this.guarded(async () => {
      await this.pick(); // waits for a reopening under way; throws if no worker has the model
      const ready = this.handles.filter((h) => h.hasModel && !h.broken);
      const nextUnit = unitCounter(n, ready.length);
      await Promise.all(ready.map((h) => this.units(h, nextUnit, { analyse: true, gcode: false }, layer, unit)));
    });
  }

  /** The vertical cut of a run of layers of the current model (flows/cut.ts). */
  cut(data: RequestData<"cut">): Promise<ResultOf<"cut">> {
    return this.guarded(async () => (await this.pick()).call("cut", data, undefined, [data.sent.buffer, data.centres.buffer]));
  }

  /** The overhang overlay of a layer (the core's rule on its droplets and the layer below's);
   *  needs no model: the least busy worker answers. The arrays are copied, not transferred. */
  unsupported(data: RequestData<"unsupported">): Promise<ResultOf<"unsupported">> {
    this.heal();
    return this.guarded(() => {
      const ready = this.handles.filter((h) => !h.broken);
      const h = ready.length ? ready.reduce((a, b) => (b.load < a.load ? b : a)) : this.handles[0];
      return h.call("unsupported", data);
    });
  }

  /** The 3D view's overhang tint for `settings` (the core's threshold); needs no model. */
  overhangFace(settings: RequestData<"overhang_face">["settings"]): Promise<number> {
    this.heal();
    return this.guarded(() => this.handles[0].call("overhang_face", { settings }));
  }

  /** The core's droplet calibration (views/calibrate.ts); needs no model. */
  calibrate(data: RequestData<"calibrate">): Promise<ResultOf<"calibrate">> {
    this.heal();
    return this.guarded(() => this.handles[0].call("calibrate", data));
  }

  /** A profile's JSON text checked by the core. */
  checkProfile(bytes: Uint8Array): Promise<ResultOf<"check_profile">> {
    this.heal();
    return this.guarded(() => this.handles[0].call("check_profile", { bytes }));
  }

  /** For tests: makes the wasm panic in one worker. */
  crash(): Promise<void> {
    return this.guarded(() => this.handles[this.handles.length - 1].call("crash", null));
  }
}

// The worker pool: one worker per core (hardwareConcurrency, 1 … 8), each with its own wasm
// instance. A slice hands the model's File to one worker, which reads and prepares the job
// (parse, weld, checks, repair) and returns the prepared mesh as transferable arrays; the
// other workers build their session from that (no import work repeated). Each worker, as soon
// as it holds the model, takes units of consecutive layers from a shared counter (two units in
// flight, so it never waits for the page between units). Layers come back as progress replies
// (buffers transferred) and are stored by index, so the page sees them in layer order however
// the workers finish; a unit's result carries its G-code as one Blob. Cancel terminates every
// worker at once, rejects what was pending and starts fresh workers.

import type {
  GcodeParseResult,
  InitResult,
  LayerData,
  OpenResult,
  PreparedMesh,
  Reply,
  RequestData,
  RequestKind,
  ResultOf,
  Settings,
  SliceFigures,
  SliceUnit,
  Summary,
} from "./protocol";

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
}

class WorkerHandle {
  private worker: Worker;
  private pending = new Map<number, Pending>();
  private nextId = 1;
  /** A crashed wasm instance cannot be trusted again. */
  broken = false;
  /** Whether the worker holds the current model. */
  hasModel = false;

  constructor() {
    this.worker = new Worker(new URL("./worker.js", import.meta.url), { type: "module", name: "dropslice" });
    this.worker.onmessage = (ev: MessageEvent<Reply>) => this.receive(ev.data);
    this.worker.onerror = (ev: ErrorEvent) => {
      ev.preventDefault();
      this.broken = true;
      this.failAll(new SliceError("crash", `the slicer worker failed: ${ev.message || "could not start"}`));
    };
  }

  get load(): number {
    return this.pending.size;
  }

  /** Sends request `kind` with its data (checked against protocol.ts `Calls`) and resolves
   *  with its typed result. */
  call<K extends RequestKind>(kind: K, data: RequestData<K>, progress?: (layer: LayerData) => void, transfer: Transferable[] = []): Promise<ResultOf<K>> {
    const id = this.nextId++;
    // one member of protocol.ts `Request`, checked by the signature (no cast)
    const message: { id: number; kind: K; data: RequestData<K> } = { id, kind, data };
    return new Promise<ResultOf<K>>((resolve, reject) => {
      this.pending.set(id, { resolve: resolve as (v: unknown) => void, reject, progress });
      this.worker.postMessage(message, transfer);
    });
  }

  private receive(reply: Reply): void {
    const p = this.pending.get(reply.id);
    if (!p) return;
    if (reply.kind === "progress") {
      p.progress?.(reply.data);
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
    this.worker.terminate();
    this.failAll(reason);
  }
}

/** One worker per core, 1 … [[MAX_WORKERS]]: preparing the job is done once, not per worker,
 *  so every worker slices from the start. */
export function defaultPoolSize(): number {
  const n = navigator.hardwareConcurrency || 1;
  return Math.max(1, Math.min(n, MAX_WORKERS));
}

export interface SliceCallbacks {
  opened(result: OpenResult): void;
  layer(layer: LayerData): void;
  /** A run of layers is complete: its G-code and summary (after all its layers). */
  unit(unit: SliceUnit): void;
  /** The prepared (placed, repaired) mesh, for the 3D view: called once, after the first
   *  worker opened the model and before `opened`; the arrays are the page's until it returns
   *  (then they are handed on to the other workers). */
  mesh?(prepared: PreparedMesh): void;
}

/** A run of consecutive layers [from, to). */
interface Unit {
  from: number;
  to: number;
}

/** Hands out the units of layers [0, layers) in order, shared by all workers. A unit is small
 *  enough to share the work evenly and to show progress, and large enough that its round trip
 *  and its Blob cost little (a Blob costs about 0.5 ms, whatever its size). */
function unitCounter(layers: number, workers: number): () => Unit | null {
  const size = Math.max(1, Math.min(16, Math.ceil(layers / (4 * workers))));
  let next = 0;
  return () => {
    if (next >= layers) return null;
    const from = next;
    next = Math.min(layers, from + size);
    return { from, to: next };
  };
}

/** Opens a model: the first worker reads the File and prepares the job (and hashes the file
 *  when asked); the others take the prepared mesh. `ready(h, r)` runs for each worker as soon
 *  as it holds the model (for the first one before the others are asked). If the first worker
 *  refuses the model, no worker is touched and every one keeps its previous model. With
 *  `mesh`, the prepared mesh is shown to it first (synchronously, before it is handed on). */
async function openAll(
  handles: WorkerHandle[],
  file: File,
  settings: Settings,
  ready: (h: WorkerHandle, r: OpenResult) => Promise<void>,
  mesh?: (prepared: PreparedMesh) => void,
): Promise<OpenResult> {
  const [first, ...others] = handles;
  const r = await first.call("open", { file, settings, hash: true, prepare: others.length > 0 || mesh !== undefined });
  for (const h of handles) h.hasModel = false;
  first.hasModel = true;
  const prepared = r.prepared;
  delete r.prepared;
  if (prepared && mesh) mesh(prepared);
  const work = [ready(first, r)];
  if (prepared && others.length > 0) {
    others.forEach((h, k) => {
      // each worker gets its own copy; the last one takes the buffers themselves
      const last = k === others.length - 1;
      const transfer = last ? [prepared.vertices.buffer, prepared.facets.buffer] : [];
      work.push(
        h.call("adopt", { prepared, settings }, undefined, transfer).then(async (o) => {
          h.hasModel = true;
          await ready(h, o);
        }),
      );
    });
  }
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

  init(): Promise<InitResult> {
    this.heal();
    return this.guarded(() => this.handles[0].call("init", null));
  }

  /** Slices a model: opens it (see [[openAll]]) and streams all layers through `cb.layer`. */
  slice(file: File, settings: Settings, cb: SliceCallbacks, analyse = false): Promise<OpenResult> {
    this.heal();
    return this.guarded(async () => {
      this.opening = null;
      let nextUnit: () => Unit | null = () => null;
      const handles = this.handles;
      return openAll(handles, file, settings, async (h, r) => {
        if (h === handles[0]) {
          nextUnit = unitCounter(r.layers, handles.length);
          cb.opened(r);
        }
        await this.units(h, nextUnit, { analyse }, cb.layer, cb.unit);
      }, cb.mesh);
    });
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

  /** Opens a model in every worker without slicing it (to browse a finished slice again
   *  after the workers were replaced by a cancel or a crash). */
  open(file: File, settings: Settings): Promise<void> {
    this.heal();
    const opening = this.guarded(async () => {
      await openAll(this.handles, file, settings, async () => {});
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

  /** The vertical cut of a run of layers of the current model (views/cut.ts). */
  cut(data: RequestData<"cut">): Promise<ResultOf<"cut">> {
    return this.guarded(async () => (await this.pick()).call("cut", data, undefined, [data.sent.buffer, data.centres.buffer]));
  }

  /** The core's droplet calibration (views/calibrate.ts); needs no model. */
  calibrate(data: RequestData<"calibrate">): Promise<ResultOf<"calibrate">> {
    this.heal();
    return this.guarded(() => this.handles[0].call("calibrate", data));
  }

  /** For tests: makes the wasm panic in one worker. */
  crash(): Promise<void> {
    return this.guarded(() => this.handles[this.handles.length - 1].call("crash", null));
  }
}

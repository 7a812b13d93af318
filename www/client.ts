// The worker pool: min(hardwareConcurrency - 1, 4) workers (at least 1), each with its own
// wasm instance. A slice opens the model in every worker at once; each worker, as soon as it
// holds the model, takes units of consecutive layers from a shared counter (two units in
// flight, so it never waits for the page between units). Layers come back as progress replies
// (buffers transferred) and are stored by index, so the page sees them in layer order however
// the workers finish; a unit's result carries its G-code as one Blob. Cancel terminates every
// worker at once, rejects what was pending and starts fresh workers.

import type { GcodeParseResult, InitResult, LayerData, OpenResult, Reply, Request, RequestKind, SliceUnit } from "./protocol";

export class SliceError extends Error {
  constructor(
    readonly kind: string,
    message: string,
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

  call<T>(kind: RequestKind, data: unknown, progress?: (layer: LayerData) => void, transfer: Transferable[] = []): Promise<T> {
    const id = this.nextId++;
    return new Promise<T>((resolve, reject) => {
      this.pending.set(id, { resolve: resolve as (v: unknown) => void, reject, progress });
      this.worker.postMessage({ id, kind, data } as Request, transfer);
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
      p.reject(new SliceError(reply.data.kind, reply.data.message));
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

export function defaultPoolSize(): number {
  const n = (navigator.hardwareConcurrency || 2) - 1;
  return Math.max(1, Math.min(n, 4));
}

export interface SliceCallbacks {
  opened(result: OpenResult): void;
  layer(layer: LayerData): void;
  /** A run of layers is complete: its G-code and summary (after all its layers). */
  unit(unit: SliceUnit): void;
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

/** Opens a model in one worker, handing it a copy of the bytes of its own (transferred, not
 *  cloned: one copy of the file per worker, made once). */
function openIn(h: WorkerHandle, stl: Uint8Array, name: string, settings: string): Promise<OpenResult> {
  const copy = stl.slice().buffer;
  return h.call<OpenResult>("open", { stl: copy, name, settings }, undefined, [copy]);
}

/** Units in flight per worker: the worker starts the next one while the page answers. */
const UNITS_IN_FLIGHT = 2;

/** Never more workers than this, whatever is asked: each holds its own copy of the model. */
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
    return this.guarded(() => this.handles[0].call<InitResult>("init", null));
  }

  /** Slices a model: opens it in every worker and streams all layers through `cb.layer`. */
  slice(stl: Uint8Array, name: string, settings: string, cb: SliceCallbacks, analyse = false): Promise<OpenResult> {
    this.heal();
    return this.guarded(async () => {
      // Every worker checks the same model and settings, so they all accept or all refuse it;
      // on refusal every worker keeps its previous model and the previous slice stays usable.
      this.opening = null;
      let first: OpenResult | null = null;
      let nextUnit: () => Unit | null = () => null;
      const handles = this.handles;
      await Promise.all(
        handles.map(async (h) => {
          const r = await openIn(h, stl, name, settings);
          if (!first) {
            first = r;
            for (const o of handles) o.hasModel = false;
            nextUnit = unitCounter(r.layers, handles.length);
            cb.opened(r);
          }
          h.hasModel = true;
          await this.units(h, nextUnit, { analyse }, cb.layer, cb.unit);
        }),
      );
      return first!;
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
        const done = await h.call<SliceUnit>("slice", { ...u, ...options }, layer);
        unit?.(done);
      }
    };
    await Promise.all(Array.from({ length: UNITS_IN_FLIGHT }, lane));
  }

  /** Opens a model in every worker without slicing it (to browse a finished slice again
   *  after the workers were replaced by a cancel or a crash). */
  open(stl: Uint8Array, name: string, settings: string): Promise<void> {
    this.heal();
    const opening = this.guarded(async () => {
      await Promise.all(
        this.handles.map(async (h) => {
          await openIn(h, stl, name, settings);
          h.hasModel = true;
        }),
      );
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
  preview(index: number): Promise<LayerData> {
    return this.guarded(async () => (await this.pick()).call<LayerData>("preview", { index }));
  }

  header(summary: string): Promise<string> {
    return this.guarded(async () => (await this.pick()).call<string>("header", { summary }));
  }

  repairs(summary: string): Promise<string[]> {
    return this.guarded(async () => (await this.pick()).call<string[]>("repairs", { summary }));
  }

  footer(summary: string): Promise<string> {
    return this.guarded(async () => (await this.pick()).call<string>("footer", { summary }));
  }

  parseGcode(file: Blob, layer: (l: LayerData) => void): Promise<GcodeParseResult> {
    this.heal();
    return this.guarded(() => this.handles[0].call<GcodeParseResult>("parse_gcode", { file }, layer));
  }

  /** Re-plans one layer with its void analysis and coverage mask. */
  previewAnalysed(index: number): Promise<LayerData> {
    return this.guarded(async () => (await this.pick()).call<LayerData>("preview", { index, analyse: true }));
  }

  /** Re-plans and analyses layers [0, n) of the current model (no G-code), spread over the
   *  workers holding it: for the void overlay after a slice made without analysis. */
  analyse(n: number, layer: (l: LayerData) => void): Promise<void> {
    return this.guarded(async () => {
      await this.pick(); // waits for a reopening under way; throws if no worker has the model
      const ready = this.handles.filter((h) => h.hasModel && !h.broken);
      const nextUnit = unitCounter(n, ready.length);
      await Promise.all(ready.map((h) => this.units(h, nextUnit, { analyse: true, gcode: false }, layer)));
    });
  }

  /** For tests: makes the wasm panic in one worker. */
  crash(): Promise<void> {
    return this.guarded(() => this.handles[this.handles.length - 1].call<void>("crash", null));
  }
}

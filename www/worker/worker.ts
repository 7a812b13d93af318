// One worker = one wasm instance = at most one Session (one prepared slicing job). The job
// worker, the pool's first, also holds the job's `Models` (its imported files), prepares the
// job from them, hands it to the other workers as bytes (`open_job` with `share`; they
// `adopt_job` it, or slice from its draft, `adopt_draft`, until `confirm_job`) and answers
// the layout and the 3D view's requests. Answers the requests of core/protocol.ts; streams layers in batches ("layers" replies, their buffers transferred).
// The model files arrive as Files and are read here (by the core, with FileReaderSync), never
// on the page's thread. Everything from the core is a typed value; its errors are thrown as
// `{kind, message, setting?}` and passed on as they are. The core's module comes compiled
// from the page as the first message (core/client.ts `compiledCore`): this worker only
// instantiates it, never fetches or compiles it.

import { Models, Session, Tally, check_profile, crash_for_test, default_settings, job_schema, overhang_face_normal_z, profile_stages, settings_schema, stage_times, unsupported_droplets, version, type InitOutput } from "../pkg/dropslice.js";
import { StageClock, publish } from "../core/stages";
import { sampleStl } from "../core/sample";
import { partsByUnit } from "../core/units";
import { GcodeError, GcodeReader, loadCore, readGcode } from "./gcode";
import { calibrateRequest } from "./calibration";
import {
  coverageMaskOf,
  isErrorValue,
  transferablesOf,
  type ErrorValue,
  type InitResult,
  type Figures,
  type LayerAnalysis,
  type OpenResult,
  type Reply,
  type Request,
  type RequestData,
  type RequestKind,
  type ResultOf,
  type ToWorker,
  type SliceUnit,
  type ModelInfo,
  type LayerData,
} from "../core/protocol";

const scope = self as unknown as DedicatedWorkerGlobalScope;
/** The per-stage profile (core/stages.ts): this worker's hand-offs and the core's counters. */
const clock = publish(
  new StageClock({
    reset: (on) => {
      if (memory) profile_stages(on);
    },
    read: () => (memory ? stage_times() : {}),
  }),
);

/** The core, once the page's module arrived and was instantiated. */
let arrived: (module: WebAssembly.Module) => void = () => {};
const wasm: Promise<InitOutput> = new Promise<WebAssembly.Module>((resolve) => (arrived = resolve)).then((module) => {
  const out = loadCore(module);
  memory = out.memory;
  return out;
});
wasm.catch(() => {}); // reported to the requests that need the core
let memory: WebAssembly.Memory | null = null;
let session: Session | null = null;
/** The job's files (the job worker's; the others take the prepared job instead). */
let models: Models | null = null;
let lastPanic = "";
let broken = false;

(globalThis as unknown as { dropslicePanic: (m: string) => void }).dropslicePanic = (m: string) => {
  lastPanic = m;
};

/** The core: waits for the page's module (the worker's first message). */
function load(): Promise<InitOutput> {
  return wasm;
}

function post(reply: Reply, transfer: Transferable[] = []): void {
  scope.postMessage(reply, transfer);
}

/** The result of request `id` of kind `K` (typed by protocol.ts `Calls`). */
function answer<K extends RequestKind>(_kind: K, id: number, data: ResultOf<K>, transfer: Transferable[] = []): void {
  post({ id, kind: "result", data }, transfer);
}

/** SHA-256 of a file, hex, computed here (for preview links). */
async function sha256Of(file: Blob): Promise<string> {
  const digest = await crypto.subtle.digest("SHA-256", await file.arrayBuffer());
  return [...new Uint8Array(digest)].map((b) => b.toString(16).padStart(2, "0")).join("");
}

/** Makes `s` this worker's session (the old one stays usable until then) and describes it. */
function adopt(s: Session): OpenResult {
  session?.free();
  session = s;
  return { layers: s.layer_count(), info: s.info() };
}

/** Lets other requests (previews) in between two layers of a long slice. */
function yieldToQueue(): Promise<void> {
  return new Promise((resolve) => {
    const ch = new MessageChannel();
    ch.port1.onmessage = () => resolve();
    ch.port2.postMessage(null);
  });
}

/** Layers per call of the supported pass. */
const SUPPORT_ITEMS = 4;

/** With `support = unitN`: the supported pass (every layer's plan with the support) in short
 *  calls, before the first layer is planned (which would otherwise make it in one call). */
function supported(s: Session): void {
  while (!timedCall("core: the supported pass, the longest call", () => s.support_step(SUPPORT_ITEMS)));
}

function layerOf(s: Session, index: number, unit: { tally: Tally } | null, analyse = false, counted = true): LayerData {
  supported(s);
  // A layer in three short calls: its section, its overhang figure (`layer_ahead`), then its
  // plan, text and arrays (the engine optimises a function only between calls).
  const r = clock.time("core: a layer (all its stages)", () => {
    while (!timedCall("core: a layer, the longest call", () => s.layer_ahead(index)));
    return timedCall("core: a layer, the longest call", () => (analyse ? s.slice_layer_analysed(index) : s.slice_layer(index)));
  });
  const t0 = performance.now();
  try {
    if (unit) {
      // the tally keeps the layer's G-code too (the unit's Blob is made from it at once)
      if (counted) unit.tally.add_layer(r);
      else unit.tally.add_analysis(r);
    }
    const roles = r.roles;
    const units = r.units;
    const layer: LayerData = {
      index: r.index,
      z: r.z,
      counts: { outer: r.outer, inner: r.inner, fill: r.fill, support: r.support, units: Array.from(r.unit_droplets), parts: partsByUnit(roles, units) },
      travelMm: r.travel_mm,
      seconds: r.seconds,
      droplets: r.droplets,
      roles,
      units,
      unsupportedArea: r.unsupported_area,
      travel: r.travel,
    };
    if (analyse) {
      layer.analysis = r.analysis() as LayerAnalysis;
      layer.mask = coverageMaskOf(r);
    }
    return layer;
  } finally {
    r.free();
    clock.since("worker: copy out of wasm", t0);
  }
}

/** Items (facets, corners, vertices) per call of the preparation: a few milliseconds of
 *  the engine's first code, less once it is optimised. */
const PREPARE_ITEMS = 16_384;

/** `Session.from_models` in short calls (`Session.begin`, then a budget of items a call):
 *  the engine keeps a running call's first code to its end, so a call that ran the whole
 *  preparation ran it all in that code; later calls of a pass get the optimised code. With
 *  `draft`, the job's draft (`Session.begin_drafted`) goes to `draft` as soon as a step made
 *  it, while the preparation goes on. */
function prepare(m: Models, job: RequestData<"open_job">["job"], draft: ((d: Uint8Array) => void) | null): Session {
  const p = timedCall("core: preparation, the longest call", () => (draft ? Session.begin_drafted(m, job) : Session.begin(m, job)));
  let done = false;
  try {
    while (!done) {
      done = timedCall("core: preparation, the longest call", () => p.step(PREPARE_ITEMS));
      const d = draft ? p.take_draft() : undefined;
      if (d && draft) draft(d);
    }
  } catch (e) {
    p.free();
    throw e;
  }
  return Session.from_preparation(p);
}

/** Triangles per call of a file's import (an STL file; OBJ and 3MF are imported in one). */
const IMPORT_ITEMS = 16_384;

/** `Models.add` in short calls (`Models.begin_add`, then a slice of the file read or a
 *  budget of triangles imported a call, `Models.finish_add`): the same model and info. */
function imported(m: Models, file: File, name: string): ModelInfo {
  const a = Models.begin_add(file, name);
  try {
    while (!timedCall("core: file read and parsed, the longest call", () => a.step(IMPORT_ITEMS)));
  } catch (e) {
    a.free();
    throw e;
  }
  return timedCall("core: file read and parsed, the longest call", () => m.finish_add(a));
}

/** Items (vertices, facets, index entries) per call of taking another worker's job. */
const TAKE_ITEMS = 65_536;

/** `Session.from_prepared` (or, with `draft`, `Session.from_draft`) in short calls
 *  (`Session.begin_take`, a budget of items read a call, `Session.from_taken`). */
function taken(bytes: Uint8Array, draft: boolean): Session {
  const name = draft ? "core: the draft taken, the longest call" : "core: the prepared job taken, the longest call";
  const t = timedCall(name, () => Session.begin_take(bytes, draft));
  try {
    while (!timedCall(name, () => t.step(TAKE_ITEMS)));
  } catch (e) {
    t.free();
    throw e;
  }
  return Session.from_taken(t);
}

/** `Session.prepared` in short calls (`Session.begin_prepared`, a budget of items written a
 *  call): the same bytes. */
function preparedBytes(s: Session): Uint8Array {
  const w = s.begin_prepared();
  try {
    while (!timedCall("core: the prepared job as bytes, the longest call", () => w.step(TAKE_ITEMS)));
    const bytes = w.take();
    if (!bytes) throw internal("the prepared job's bytes were not written");
    return bytes;
  } finally {
    w.free();
  }
}

/** Runs one call into the core, keeping the longest of `name` in the profile. */
function timedCall<T>(name: string, f: () => T): T {
  const t0 = performance.now();
  try {
    return f();
  } finally {
    clock.max(name, performance.now() - t0);
  }
}

/** The unit being sliced: the next one starts when it ends. */
let slicing: Promise<void> = Promise.resolve();

/** A batch of layers is posted (and other requests let in) once it is this old, ms: a
 *  message per layer cost about a tenth of the worker's time, and as much on the page's thread. */
const BATCH_MS = 25;

/** Slices layers [from, to): batches of layers as "layers" replies, then the unit's G-code and
 *  summary. With `gcode: false` (an analysis after the slice) the summary holds only the
 *  layers' analysis. */
async function sliceUnit(id: number, req: RequestData<"slice">): Promise<void> {
  const s = need();
  const { from, to } = req;
  const counted = req.gcode ?? true;
  // a job too large to analyse (the core's bound on a layer's memory): a slice goes on
  // without the analysis, the analysis pass alone says why
  const refusal = req.analyse ? (s.analysis_refusal() as ErrorValue | null) : null;
  if (refusal && !counted) throw refusal;
  const analyse = req.analyse && !refusal;
  const parts = { tally: new Tally() };
  let batch: LayerData[] = [];
  let since = performance.now();
  try {
    for (let i = from; i < to; i++) {
      batch.push(layerOf(s, i, parts, analyse, counted));
      if (i + 1 < to && performance.now() - since < BATCH_MS) continue;
      const sent = batch;
      batch = [];
      clock.time("worker: post", () => post({ id, kind: "layers", data: sent }, sent.flatMap(transferablesOf)));
      const t0 = performance.now();
      await yieldToQueue();
      clock.since("worker: yield to the queue", t0);
      since = performance.now();
      if (session !== s) throw internal("the model was replaced during slicing");
    }
    // the 3D estimate's slabs at the unit's ends (the layers next to it are planned again)
    if (analyse) clock.time("core: the unit's end slabs", () => s.finish_slabs(parts.tally));
    const unit: SliceUnit = { from, to, summary: parts.tally.summary() };
    // the Blob copies the view of the module's memory at once (no call into the module between)
    if (counted) unit.gcode = clock.time("worker: blob", () => new Blob([parts.tally.gcode_view()] as BlobPart[], { type: "text/plain" }));
    answer("slice", id, unit);
  } finally {
    parts.tally.free();
  }
}

/** A bug of the page or the worker, as an error value. */
function internal(message: string): ErrorValue {
  return { kind: "internal", message: `internal error (a bug in dropslice, please report it): ${message}` };
}

/** Compiles the layer path before a job needs it: the engine compiles a function on its first
 *  call (the module is shared, so once for every worker), and a worker waiting for the job
 *  worker's draft does it meanwhile rather than in the job's first layer. The sample part (a
 *  block with a hole and a boss: loops, a hole, fill) prepared, two lower layers sliced with their
 *  text, all dropped; nothing of this worker's own job is touched. */
function warmUp(): void {
  const { bytes, name } = sampleStl();
  const s = new Session(bytes, name, {});
  try {
    const i = Math.max(1, Math.floor(s.layer_count() / 4));
    s.layer_ahead(i - 1);
    s.slice_layer(i - 1).free();
    while (!s.layer_ahead(i));
    s.slice_layer(i).free();
  } finally {
    s.free();
  }
}

function needModels(): Models {
  if (!models) throw internal("no model files were added in this worker");
  return models;
}

function need(): Session {
  if (!session) throw internal("no model is open in this worker");
  return session;
}

async function handle(req: Request): Promise<void> {
  switch (req.kind) {
    case "init": {
      await load();
      const result: InitResult = { version: version(), schema: settings_schema(), job: job_schema(), defaults: default_settings() };
      answer(req.kind, req.id, result);
      return;
    }
    case "models_add": {
      await load();
      models ??= new Models();
      const infos: ModelInfo[] = [];
      const sha256: string[] = [];
      const hashing = req.data.hash ?? true;
      const m = models;
      try {
        for (const { name, file } of req.data.files) {
          const hash = hashing ? sha256Of(file) : null;
          infos.push(clock.time("worker: file read and parsed", () => imported(m, file, name)));
          if (hash) {
            const t0 = performance.now();
            sha256.push(await hash);
            clock.since("worker: waiting for SHA-256", t0);
          }
        }
      } catch (e) {
        // None of the files asked for stays (an earlier file of that name neither): a job
        // opened right after (its request is already queued) finds them missing and is
        // refused, instead of being prepared from what the worker held before.
        for (const { name } of req.data.files) m.remove(name);
        throw e;
      }
      answer(req.kind, req.id, { infos, sha256 });
      return;
    }
    case "models_remove": {
      for (const name of req.data.names) models?.remove(name);
      answer(req.kind, req.id, undefined);
      return;
    }
    case "display_mesh": {
      const { name, item, max } = req.data;
      const mesh = needModels().display_mesh(name, item, max);
      answer(req.kind, req.id, mesh, [mesh.buffer]);
      return;
    }
    case "layout":
      answer(req.kind, req.id, needModels().layout(req.data.job));
      return;
    case "lay_flat":
      answer(req.kind, req.id, needModels().lay_flat(req.data.name, req.data.item) as { rotate_x: number; rotate_y: number });
      return;
    case "orient":
      answer(req.kind, req.id, needModels().orient(req.data.job, req.data.part));
      return;
    case "check_profile":
      await load();
      answer(req.kind, req.id, check_profile(req.data.bytes));
      return;
    case "open_job": {
      await load();
      // one copy of the prepared job (or of its draft and the confirmation) per other worker
      // (at most the pool's), made here rather than on the page's thread, all transferred
      const asked = req.data.share ?? 0;
      const n = Number.isFinite(asked) ? Math.min(Math.max(0, Math.floor(asked)), 8) : 0;
      const copies = (first: Uint8Array): Uint8Array[] => [first, ...Array.from({ length: n - 1 }, () => first.slice())];
      const drafted =
        n > 0 && req.data.draft
          ? (d: Uint8Array) => {
              const drafts = clock.time("worker: the draft's copies", () => copies(d));
              post({ id: req.id, kind: "draft", data: { drafts } }, drafts.map((p) => p.buffer));
            }
          : null;
      // the old session stays usable if the job is refused
      const s = prepare(needModels(), req.data.job, drafted);
      // made before the session is taken, so a failure keeps the old one
      let shared: { prepared: Uint8Array[] } | { confirm: Uint8Array[] } | null = null;
      try {
        const table = drafted ? s.confirmation() : undefined;
        if (table) shared = { confirm: copies(table) };
        else if (n > 0) shared = { prepared: copies(clock.time("core: the prepared job as bytes", () => preparedBytes(s))) };
      } catch (e) {
        s.free();
        throw e;
      }
      const opened = adopt(s);
      if (!shared) answer(req.kind, req.id, opened);
      else {
        const buffers = ("confirm" in shared ? shared.confirm : shared.prepared).map((p) => p.buffer);
        answer(req.kind, req.id, { ...opened, ...shared }, buffers);
      }
      return;
    }
    case "adopt_job": {
      await load();
      answer(req.kind, req.id, adopt(taken(req.data.prepared, false)));
      return;
    }
    case "adopt_draft": {
      await load();
      const s = taken(req.data.prepared, true);
      session?.free();
      session = s;
      answer(req.kind, req.id, { layers: s.layer_count() });
      return;
    }
    case "confirm_job": {
      const s = need();
      s.confirm(req.data.table);
      answer(req.kind, req.id, { layers: s.layer_count(), info: s.info() });
      return;
    }
    case "slice": {
      // Units run one after the other (the page keeps two in flight); previews still get in
      // between two layers.
      const run = slicing.then(() => sliceUnit(req.id, req.data));
      slicing = run.catch(() => {});
      await run;
      return;
    }
    case "preview": {
      const s = need();
      // a job too large to analyse is previewed without (the analysis pass said why)
      const layer = layerOf(s, req.data.index, null, req.data.analyse && s.analysis_refusal() === null);
      post({ id: req.id, kind: "result", data: layer }, transferablesOf(layer));
      return;
    }
    case "header":
      answer(req.kind, req.id, need().header(req.data.summary));
      return;
    case "footer":
      answer(req.kind, req.id, need().footer(req.data.summary));
      return;
    case "figures":
      answer(req.kind, req.id, need().figures(req.data.parts));
      return;
    case "hash":
      answer(req.kind, req.id, await sha256Of(req.data.file));
      return;
    case "parse_gcode": {
      let fraction = 0;
      const reader = new GcodeReader((layer) =>
        post({ id: req.id, kind: "progress", data: { ...layer, fraction } }, transferablesOf(layer)),
      );
      await readGcode(req.data.file, reader, (f) => (fraction = f));
      let figures: Figures | null = null;
      let figuresError: string | null = null;
      try {
        figures = reader.figures();
      } catch (e) {
        figuresError = (e as { message?: string })?.message ?? String(e);
      }
      let settings: Record<string, number | boolean | string> | null = null;
      let settingsError: string | null = null;
      try {
        settings = reader.headerSettings();
      } catch (e) {
        settingsError = (e as { message?: string })?.message ?? String(e);
      }
      answer(req.kind, req.id, {
        figures,
        figuresError,
        figuresNote: figures ? reader.figuresNote() : null,
        settings,
        settingsError,
        layers: reader.layers,
        dropletWidth: reader.dropletWidth,
        layerHeight: Number(reader.header.layer_height),
        header: reader.header,
      });
      return;
    }
    case "unsupported": {
      await load();
      const { droplets, units, below, widths, limitMm } = req.data;
      const mask = unsupported_droplets(droplets, units, below?.droplets ?? new Float32Array(0), below?.units ?? new Uint8Array(0), Float64Array.from(widths), limitMm, below === null);
      answer(req.kind, req.id, mask, [mask.buffer]);
      return;
    }
    case "warm":
      await load();
      clock.time("worker: warm-up (the sample part's layer)", () => clock.aside(warmUp));
      answer(req.kind, req.id, null);
      return;
    case "overhang_face":
      await load();
      answer(req.kind, req.id, overhang_face_normal_z(req.data.settings));
      return;
    case "cut": {
      const { line, from, to, sent, centres } = req.data;
      const s = need();
      supported(s);
      const r = s.cut(Float64Array.from(line), from, to, sent, centres);
      try {
        const reply = { droplets: r.droplets, spans: r.spans, voids: r.voids, bands: r.bands };
        answer(req.kind, req.id, reply, [reply.droplets.buffer, reply.spans.buffer, reply.voids.buffer]);
      } finally {
        r.free();
      }
      return;
    }
    case "calibrate":
      await load();
      answer(req.kind, req.id, await calibrateRequest(req.data));
      return;
    case "crash":
      await load();
      crash_for_test();
      return;
  }
}

/** What ran out of memory, by the request that did: the model's size or complexity (reading
 * or preparing it), the layers' complexity (slicing; layers are made one at a time, so their
 * number is not the cause) or the void analysis. */
function outOfMemory(req: Request | null): string {
  const limit = "the slicer ran out of memory (a browser tab's WebAssembly is limited to 4 GB)";
  const model =
    "the model is too large or too complex: too many triangles, or not a closed surface (loose triangles). Simplify or repair it in a mesh tool, or print fewer copies.";
  switch (req?.kind) {
    case "models_add":
    case "display_mesh":
    case "layout":
    case "lay_flat":
    case "orient":
    case "open_job":
    case "adopt_job":
    case "adopt_draft":
    case "confirm_job":
      return `${limit} while reading and preparing the model: ${model}`;
    case "slice":
    case "preview":
      return req.data.analyse
        ? `${limit} while analysing the voids: slice without the Voids analysis, or slice a smaller part.`
        : `${limit} while slicing a layer: ${model}`;
    case "cut":
      return `${limit} while making the cut's section: ${model}`;
    case "parse_gcode":
    case "calibrate":
      return `${limit} while reading the G-code file: the file is too large for the page.`;
    default:
      return `${limit}: ${model}`;
  }
}

function describe(e: unknown, req: Request | null = null): ErrorValue {
  if (e instanceof GcodeError) return { kind: "import", message: `cannot read the G-code file: ${e.message}` };
  if (e instanceof WebAssembly.RuntimeError || e instanceof RangeError) {
    broken = true;
    const big = memory !== null && memory.buffer.byteLength > 1.5 * 2 ** 30;
    if (lastPanic) return { kind: "crash", message: `the slicer crashed (a bug in dropslice, please report it): ${lastPanic}` };
    if (big || /memory|allocation|out of bounds/i.test(String(e))) {
      return {
        kind: "crash",
        message: outOfMemory(req),
      };
    }
    return { kind: "crash", message: `the slicer stopped unexpectedly (${String(e)}). Please report it.` };
  }
  if (isErrorValue(e)) return { kind: e.kind, message: e.message, ...(e.setting ? { setting: e.setting } : {}) };
  return internal(e instanceof Error ? e.message : String(e));
}

scope.onmessage = (ev: MessageEvent<ToWorker>) => {
  const msg = ev.data;
  if (msg.kind === "module") {
    // instantiated at once, before any request (they arrive after it), so that a worker asked
    // to open a job does not instantiate the module only then; a failure is reported to the
    // first request that needs the core
    arrived(msg.module);
    return;
  }
  const req: Request = msg;
  if (broken) {
    post({ id: req.id, kind: "error", data: { kind: "crash", message: "this worker crashed earlier" } });
    return;
  }
  handle(req).catch((e: unknown) => post({ id: req.id, kind: "error", data: describe(e, req) }));
};

// One worker = one wasm instance = at most one Session (one prepared slicing job).
// Answers the requests of protocol.ts; streams layers as "progress" replies with their
// buffers transferred.

import init, {
  Session,
  crash_for_test,
  default_settings_json,
  settings_schema,
  version,
  type InitOutput,
} from "./pkg/dropslice.js";
import { GcodeError, GcodeReader, readGcode } from "./gcode";
import { addNumbers, coverageMaskOf, splitError, transferablesOf, type LayerData, type Reply, type Request, type SliceUnit } from "./protocol";

const scope = self as unknown as DedicatedWorkerGlobalScope;

let wasm: Promise<InitOutput> | null = null;
let memory: WebAssembly.Memory | null = null;
let session: Session | null = null;
let lastPanic = "";
let broken = false;

(globalThis as unknown as { dropslicePanic: (m: string) => void }).dropslicePanic = (m: string) => {
  lastPanic = m;
};

function load(): Promise<InitOutput> {
  if (!wasm) {
    wasm = init({ module_or_path: new URL("./dropslice_bg.wasm", import.meta.url) }).then((out) => {
      memory = out.memory;
      return out;
    });
  }
  return wasm;
}

function post(reply: Reply, transfer: Transferable[] = []): void {
  scope.postMessage(reply, transfer);
}

/** Lets other requests (previews) in between two layers of a long slice. */
function yieldToQueue(): Promise<void> {
  return new Promise((resolve) => {
    const ch = new MessageChannel();
    ch.port1.onmessage = () => resolve();
    ch.port2.postMessage(null);
  });
}

/** What a layer adds to its unit: G-code bytes and the core's summary. */
interface UnitParts {
  gcode: Uint8Array[];
  summary: Record<string, unknown>;
}

function layerOf(s: Session, index: number, unit: UnitParts | null, analyse = false): LayerData {
  const r = analyse ? s.slice_layer_analysed(index) : s.slice_layer(index);
  try {
    if (unit) {
      unit.gcode.push(r.gcode);
      addNumbers(unit.summary, JSON.parse(r.summary_json) as Record<string, unknown>);
    }
    const layer: LayerData = {
      index: r.index,
      z: r.z,
      counts: { outer: r.outer, inner: r.inner, fill: r.fill },
      travelMm: r.travel_mm,
      droplets: r.droplets,
      roles: r.roles,
      travel: r.travel,
    };
    if (analyse) {
      layer.analysis = JSON.parse(r.analysis_json);
      layer.mask = coverageMaskOf(r);
    }
    return layer;
  } finally {
    r.free();
  }
}

/** The unit being sliced: the next one starts when it ends. */
let slicing: Promise<void> = Promise.resolve();

async function sliceUnit(id: number, req: Extract<Request, { kind: "slice" }>["data"]): Promise<void> {
  const s = need();
  const { from, to } = req;
  const parts: UnitParts | null = (req.gcode ?? true) ? { gcode: [], summary: {} } : null;
  for (let i = from; i < to; i++) {
    const layer = layerOf(s, i, parts, req.analyse);
    post({ id, kind: "progress", data: layer }, transferablesOf(layer));
    await yieldToQueue();
    if (session !== s) throw new Error("internal: the model was replaced during slicing");
  }
  const unit: SliceUnit = { from, to };
  if (parts) {
    unit.gcode = new Blob(parts.gcode as BlobPart[], { type: "text/plain" });
    unit.summary = parts.summary;
  }
  post({ id, kind: "result", data: unit });
}

function need(): Session {
  if (!session) throw new Error("internal: no model is open in this worker");
  return session;
}

async function handle(req: Request): Promise<void> {
  switch (req.kind) {
    case "init": {
      await load();
      post({
        id: req.id,
        kind: "result",
        data: { version: version(), schema: JSON.parse(settings_schema()), defaults: JSON.parse(default_settings_json()) },
      });
      return;
    }
    case "open": {
      await load();
      // the old session stays usable if the new model or settings are refused
      const s = new Session(new Uint8Array(req.data.stl), req.data.name, req.data.settings);
      session?.free();
      session = s;
      post({ id: req.id, kind: "result", data: { layers: s.layer_count(), info: JSON.parse(s.info_json()) } });
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
      const layer = layerOf(need(), req.data.index, null, req.data.analyse);
      post({ id: req.id, kind: "result", data: layer }, transferablesOf(layer));
      return;
    }
    case "header":
      post({ id: req.id, kind: "result", data: need().header(req.data.summary) });
      return;
    case "repairs":
      post({ id: req.id, kind: "result", data: JSON.parse(need().repairs(req.data.summary)) });
      return;
    case "footer":
      post({ id: req.id, kind: "result", data: need().footer(req.data.summary) });
      return;
    case "parse_gcode": {
      let fraction = 0;
      const reader = new GcodeReader((layer) =>
        post({ id: req.id, kind: "progress", data: { ...layer, fraction } }, transferablesOf(layer)),
      );
      await readGcode(req.data.file, reader, (f) => (fraction = f));
      post({
        id: req.id,
        kind: "result",
        data: {
          layers: reader.layers,
          dropletWidth: reader.dropletWidth,
          layerHeight: Number(reader.header.layer_height),
          header: reader.header,
        },
      });
      return;
    }
    case "crash":
      await load();
      crash_for_test();
      return;
  }
}

function describe(e: unknown): { kind: string; message: string } {
  if (e instanceof GcodeError) return { kind: "import", message: `cannot read the G-code file: ${e.message}` };
  if (e instanceof WebAssembly.RuntimeError || e instanceof RangeError) {
    broken = true;
    const big = memory !== null && memory.buffer.byteLength > 1.5 * 2 ** 30;
    if (lastPanic) return { kind: "crash", message: `the slicer crashed (a bug in dropslice, please report it): ${lastPanic}` };
    if (big || /memory|allocation|out of bounds/i.test(String(e))) {
      return {
        kind: "crash",
        message: "the slicer ran out of memory (a browser tab's WebAssembly is limited to 4 GB). Try fewer layers (a larger layer height) or a smaller part.",
      };
    }
    return { kind: "crash", message: `the slicer stopped unexpectedly (${String(e)}). Please report it.` };
  }
  if (e instanceof Error) return splitError(e.message);
  return splitError(String(e));
}

scope.onmessage = (ev: MessageEvent<Request>) => {
  const req = ev.data;
  if (broken) {
    post({ id: req.id, kind: "error", data: { kind: "crash", message: "this worker crashed earlier" } });
    return;
  }
  handle(req).catch((e: unknown) => post({ id: req.id, kind: "error", data: describe(e) }));
};

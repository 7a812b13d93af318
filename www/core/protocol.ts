// Messages between the page (client.ts) and a worker (worker/worker.ts).
// Every request is {id, kind, data}; the worker answers with any number of
// "progress" replies (a slice's: "layers", a batch of layers in one message) and then exactly
// one "result" or "error" reply with the same id.
//
// The values the core hands out (model info, layouts, job info, summaries, figures, layer
// analyses, the settings schema, calibrations, errors) are typed by the core itself: their
// declarations are generated from the Rust types (tsify) into the wasm glue's
// ../pkg/dropslice.d.ts by scripts/build.sh, and re-exported here. Only what the page and
// its workers make themselves is declared below.

import type {
  Angles,
  Calibration,
  Counts,
  CutResult,
  ErrorReport,
  Figures,
  JobInfo,
  JobSchema,
  LayerAnalysis,
  Layout,
  Orientations,
  Profile,
  ModelInfo,
  PartSpec,
  SettingSpec,
  SliceFigures,
  Summary,
} from "../pkg/dropslice.js";

import type { RawSettings } from "./settings";

// Every type the core generates (tsify) is part of the protocol.
export type * from "../pkg/dropslice.js";

/** A job file (docs/jobs.md): the job's settings (no part keys) and its parts. */
export interface JobFile {
  settings: RawSettings;
  parts: PartSpec[];
}

/** A layer's droplets as the core counts them (by role, the support, unit 1's), and those of
 *  each unit's parts (the support not included: units.ts `partsByUnit`, index u is unit u's). */
export type LayerCounts = Counts & { parts: number[] };

/** One layer as drawn: flat arrays, never an object per droplet. */
export interface LayerData {
  index: number;
  z: number;
  counts: LayerCounts;
  travelMm: number;
  /** The core's estimated print time of the layer, s (src/output/summary.rs `layer_seconds`; the
   *  layers' times add up to the job's `print_seconds`). Absent for a .gco file's layers. */
  seconds?: number;
  /** x,y pairs in mm, every droplet (each one of a G25 line too). */
  droplets: Float32Array;
  /** 0 outermost loop, 1 inner loops, 2 fill, 3 support; one per droplet. */
  roles: Uint8Array;
  /** The discharge unit of each droplet (0 … units − 1). */
  units: Uint8Array;
  /** The layer's overhang area, mm² (the core's, slices only). */
  unsupportedArea?: number;
  /** x0,y0,x1,y1 per travel move, mm. */
  travel: Float32Array;
  /** Share of the input read so far, 0..1 (.gco files only). */
  fraction?: number;
  /** The void analysis (src/analysis/), when the request asked for it. */
  analysis?: LayerAnalysis;
  /** Coverage mask of the analysis (cells of B/4). */
  mask?: CoverageMask;
}

/** The analysis' coverage mask: square cells of `cell` mm, in tiles only where the layer's
 *  region and droplets are (parts far apart cost nothing for the space between them). */
export interface CoverageMask {
  cell: number;
  tiles: MaskTile[];
}

/** Per square cell (col, row) from `origin` + (col, row)·cell: the share 0..255 of it that
 *  is void / overfill; row-major, row 0 at the lowest y. `overfill` is empty when the tile
 *  has none (it is rare). */
export interface MaskTile {
  origin: [number, number];
  width: number;
  height: number;
  void: Uint8Array;
  overfill: Uint8Array;
}

/** The mask from the core's flat arrays (src/wasm/layer.rs: `mask_cell`, `mask_tiles` = origin x,
 *  origin y, width, height per tile, `void_mask` and `overfill_mask` = the tiles' shares one
 *  after the other, `mask_overfilled` = per tile whether it has overfill). The tiles' void
 *  shares are views of one buffer (one copy out of the core per layer); overfill shares are
 *  copied only for the tiles that have some. */
export function coverageMaskOf(r: {
  mask_cell: number;
  mask_tiles: Float64Array;
  void_mask: Uint8Array;
  overfill_mask: Uint8Array;
  mask_overfilled: Uint8Array;
}): CoverageMask {
  const frames = r.mask_tiles;
  const voids = r.void_mask;
  const overfilled = r.mask_overfilled;
  const overfill = overfilled.includes(1) ? r.overfill_mask : null;
  const tiles: MaskTile[] = [];
  let at = 0;
  for (let i = 0, t = 0; i + 3 < frames.length; i += 4, t++) {
    const [x, y, width, height] = [frames[i], frames[i + 1], frames[i + 2], frames[i + 3]];
    const end = at + width * height;
    tiles.push({
      origin: [x, y],
      width,
      height,
      void: voids.subarray(at, end),
      overfill: overfill && overfilled[t] ? overfill.slice(at, end) : new Uint8Array(0),
    });
    at = end;
  }
  return { cell: r.mask_cell, tiles };
}

/** An error as the core throws it (`ErrorReport`: import, setting, job, nothing_to_print,
 *  io, internal, …) and as a worker replies it; `crash` and `link` are the page's own kinds. */
export type ErrorValue = ErrorReport;


/** The result of a "slice" request: what belongs to its run of layers as a whole. */
export interface SliceUnit {
  from: number;
  to: number;
  /** The G-code of layers [from, to), in order (absent when the request asked for none). */
  gcode?: Blob;
  /** The core's summary of these layers (with `gcode: false` only their analysis). */
  summary: Summary;
}

export interface InitResult {
  version: string;
  schema: SettingSpec[];
  /** The numbers a job's part carries, their ranges and the job's counts. */
  job: JobSchema;
  defaults: RawSettings;
}

export interface OpenResult {
  layers: number;
  info: JobInfo;
  /** SHA-256 of the file, hex (when asked for). */
  sha256?: string;
}

export interface GcodeParseResult {
  layers: number;
  dropletWidth: number;
  layerHeight: number;
  header: Record<string, string>;
  /** The file's figures with its header's settings (the core's `GcodeStream.figures`), or
   *  null and the reason why the header does not give them. */
  figures: Figures | null;
  figuresError: string | null;
  /** Why `figures` are computed from the commands (null: they are the header's own, the
   *  figures of the slice that wrote the file). */
  figuresNote: string | null;
  /** The settings the header names, typed and checked by the core (`GcodeStream.header_settings`),
   *  or null and the reason. */
  settings: RawSettings | null;
  settingsError: string | null;
}

/** Every request a worker answers: what it is sent and what it replies. */
export interface Calls {
  init: { data: null; result: InitResult };
  slice: { data: { from: number; to: number; analyse?: boolean; gcode?: boolean }; result: SliceUnit };
  preview: { data: { index: number; analyse?: boolean }; result: LayerData };
  header: { data: { summary: Summary | null }; result: string };
  footer: { data: { summary: Summary }; result: string };
  figures: { data: { parts: Summary[] }; result: SliceFigures };
  /** SHA-256 of a file, hex (computed in the worker). */
  hash: { data: { file: Blob }; result: string };
  parse_gcode: { data: { file: Blob }; result: GcodeParseResult };
  crash: { data: null; result: void };
  /** Build jobs (each worker's `Models`, src/wasm/mod.rs): files added under their job names
   *  (a name already there is replaced), with their info and SHA-256. */
  /** `hash: false`: no SHA-256 here (`sha256` empty; the pool has another worker hash the
   *  files meanwhile, or needs no hash). */
  models_add: { data: { files: { name: string; file: File }[]; hash?: boolean }; result: { infos: ModelInfo[]; sha256: string[] } };
  models_remove: { data: { names: string[] }; result: void };
  /** A decimated copy of a file's (or 3MF item's) triangles for the 3D view (9 floats each). */
  display_mesh: { data: { name: string; item?: number; max: number }; result: Float32Array };
  layout: { data: { job: JobFile }; result: Layout };
  lay_flat: { data: { name: string; item?: number }; result: Angles };
  /** The candidate orientations of `job.parts[part]`, best first (src/wasm/models.rs `orient`). */
  orient: { data: { job: JobFile; part: number }; result: Orientations };
  /** A profile file's bytes decoded and checked by the core (`check_profile`: UTF-8, or UTF-16
   *  with a byte-order mark; the CLI's `--profile` reads them alike); needs no model. */
  check_profile: { data: { bytes: Uint8Array }; result: Profile };
  /** Prepares the job `job` of the files added (Session.from_models), in the job worker;
   *  with `share: n`, also n copies of the prepared job as bytes (`Session.prepared`), one for
   *  each other worker's `adopt_job`. With `draft` too, n copies of the job's draft in a
   *  "draft" reply as soon as its parts are merged (`Session.begin_drafted`), and then, if the
   *  job is the draft's, n confirmations (`confirm`, for `confirm_job`) instead of `prepared`. */
  open_job: { data: { job: JobFile; share?: number; draft?: boolean }; result: OpenResult & { prepared?: Uint8Array[]; confirm?: Uint8Array[] } };
  /** Takes the job worker's draft of the job (`Session.from_draft`: the job as its parts were
   *  merged and indexed), to slice layers from before the job is made; the
   *  page keeps those layers until `confirm_job`. */
  adopt_draft: { data: { prepared: Uint8Array }; result: { layers: number } };
  /** Takes the job worker's confirmation that the job is the draft's (`Session.confirm`):
   *  the draft's layers stand, the session has the job's info. */
  confirm_job: { data: { table: Uint8Array }; result: OpenResult };
  /** Takes the job the job worker prepared (`Session.from_prepared`): no file is read, nothing
   *  prepared again. */
  adopt_job: { data: { prepared: Uint8Array }; result: OpenResult };
  /** The overhang overlay of a layer: 1 per droplet without a droplet of the layer below
   *  within the rule (src/wasm/mod.rs `unsupported_droplets`); `below` null for the first layer. */
  unsupported: { data: UnsupportedRequest; result: Uint8Array };
  /** Compiles the layer path ahead of a job (`warmUp` in worker.ts): the sample part prepared
   *  and one of its layers sliced, then dropped. Asked of the workers that wait for the job
   *  worker's draft or job, once each. */
  warm: { data: Record<string, never>; result: null };
  /** The 3D view's overhang tint: faces with normal z below minus this overhang. */
  overhang_face: { data: { settings: RawSettings }; result: number };
  /** The vertical cut of layers [from, to) (flows/cut.ts, src/wasm/cut.rs `Session.cut`). */
  cut: { data: CutRequest; result: CutReply };
  /** The droplet size from a printed part's mass (views/calibrate.ts, src/output/calibrate.rs). */
  calibrate: { data: CalibrateRequest; result: Calibration };
}

/** A calibration: of a slice (its droplet total, H and aspect as sliced; the core's
 *  `calibrate`) or of a .gco file (re-read by the core's counting reader: its header's count,
 *  else its commands', its H and aspect; `density` null: the header's). Refusals are errors
 *  of kind "calibration" (the core's message); a file it cannot read, kind "import". */
export type CalibrateRequest =
  | { from: "slice"; droplets: number; layer_height: number; droplet_aspect: number; mass: number; density: number }
  | { from: "gcode"; file: Blob; mass: number; density: number | null };

/** A layer's droplets and units, the layer below's (null: the first layer), the droplet widths
 *  of each unit [B, B₁, …] and `overhang_limit`·B (mm). */
export interface UnsupportedRequest {
  droplets: Float32Array;
  units: Uint8Array;
  below: { droplets: Float32Array; units: Uint8Array } | null;
  widths: number[];
  limitMm: number;
}

/** A vertical cut along `line` = [ax, ay, bx, by] for layers [from, to): `sent` per layer of
 *  [from − 1, to + 1) within the part, the droplet centres sent in `centres` (x, y pairs, every
 *  droplet within B of the line), or [[NOT_SENT]] for a layer the worker plans itself. */
export interface CutRequest {
  line: [number, number, number, number];
  from: number;
  to: number;
  sent: Uint32Array;
  centres: Float64Array;
}
export const NOT_SENT = 0xffffffff;

/** The core's `CutResult` (src/wasm/cut.rs) as plain arrays: droplets (layer, t, d, role,
 *  unit; only layers not sent), spans (layer, t0, t1), voids (layer, band, t0, t1) of `bands`
 *  heights per slab. */
export type CutReply = Pick<CutResult, "droplets" | "spans" | "voids" | "bands">;

export type RequestKind = keyof Calls;
export type RequestData<K extends RequestKind> = Calls[K]["data"];
export type ResultOf<K extends RequestKind> = Calls[K]["result"];

export type Request = { [K in RequestKind]: { id: number; kind: K; data: RequestData<K> } }[RequestKind];

/** A worker's first message: the core's module, compiled once by the page (core/client.ts
 *  `compiledCore`); the worker instantiates it and never fetches or compiles the module. */
export interface ModuleMessage {
  kind: "module";
  module: WebAssembly.Module;
}

/** What the page posts to a worker. */
export type ToWorker = ModuleMessage | Request;

export type Reply =
  | { id: number; kind: "progress"; data: LayerData }
  | { id: number; kind: "layers"; data: LayerData[] }
  /** During `open_job` with `draft`: one copy of the job's draft per other worker. */
  | { id: number; kind: "draft"; data: { drafts: Uint8Array[] } }
  | { id: number; kind: "result"; data: ResultOf<RequestKind> }
  | { id: number; kind: "error"; data: ErrorValue };

/** Whether a thrown value is an error object of the core (`{kind, message, setting?}`). */
export function isErrorValue(e: unknown): e is ErrorValue {
  return typeof e === "object" && e !== null && typeof (e as ErrorValue).kind === "string" && typeof (e as ErrorValue).message === "string";
}

export function transferablesOf(layer: LayerData): Transferable[] {
  const out = [layer.droplets.buffer, layer.roles.buffer, layer.units.buffer, layer.travel.buffer] as Transferable[];
  // the tiles' shares may be views of one buffer: each buffer once
  const buffers = new Set<ArrayBufferLike>();
  for (const t of layer.mask?.tiles ?? []) buffers.add(t.void.buffer).add(t.overfill.buffer);
  for (const b of buffers) out.push(b as Transferable);
  return out;
}

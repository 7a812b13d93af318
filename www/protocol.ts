// Messages between the page (client.ts) and a worker (worker.ts).
// Every request is {id, kind, data}; the worker answers with any number of
// "progress" replies and then exactly one "result" or "error" reply with the same id.

export interface Counts {
  outer: number;
  inner: number;
  fill: number;
}

/** Where a slice came from and what the core said about the mesh. */
export interface JobInfo {
  file_name?: string;
  mesh?: { facets_in_file: number; facets: number; vertices: number; open_edges: number };
  droplet_width?: number;
  bounds?: { min: [number, number, number]; max: [number, number, number] };
  layers?: number;
  warnings?: string[];
  /** Scale for x, y and z when the size suggests inches (25.4) or micrometres (0.001). */
  suggested_scale?: number | null;
  [key: string]: unknown;
}

/** One layer as drawn: flat arrays, never an object per droplet. */
export interface LayerData {
  index: number;
  z: number;
  counts: Counts;
  travelMm: number;
  /** x,y pairs in mm, every droplet (each one of a G25 line too). */
  droplets: Float32Array;
  /** 0 outermost loop, 1 inner loops, 2 fill; one per droplet. */
  roles: Uint8Array;
  /** x0,y0,x1,y1 per travel move, mm. */
  travel: Float32Array;
  /** Share of the input read so far, 0..1 (.gco files only). */
  fraction?: number;
  /** The void analysis (src/analysis.rs), when the request asked for it. */
  analysis?: LayerAnalysis;
  /** Coverage mask of the analysis (cells of B/4). */
  mask?: CoverageMask;
}

/** One connected void of a layer (src/analysis.rs `Void`); areas mm², points mm. */
export interface Void {
  area: number;
  centroid: [number, number];
  min: [number, number];
  max: [number, number];
  at_boundary: boolean;
}

/** What a layer's droplets cover of its region (src/analysis.rs `LayerAnalysis`). */
export interface LayerAnalysis {
  index: number;
  region_area: number;
  covered_area: number;
  coverage: number;
  void_area: number;
  enclosed_void_area: number;
  voids: number;
  largest_void: Void | null;
  overfill_area: number;
  boundary_deviation: number;
  [key: string]: unknown;
}

/** Per square cell (col, row) from `origin` + (col, row)·cell: the share 0..255 of it that
 *  is void / overfill; row-major, row 0 at the lowest y. */
export interface CoverageMask {
  origin: [number, number];
  cell: number;
  width: number;
  height: number;
  void: Uint8Array;
  overfill: Uint8Array;
}

/** The result of a "slice" request: what belongs to its run of layers as a whole. */
export interface SliceUnit {
  from: number;
  to: number;
  /** The G-code of layers [from, to), in order (absent when the request asked for none). */
  gcode?: Blob;
  /** The core's Summary of these layers, summed (the page adds the units up for the header). */
  summary?: Record<string, unknown>;
}

export interface SettingSpec {
  name: string;
  kind: "number" | "integer" | "bool" | "enum";
  unit: string;
  min: number | null;
  max: number | null;
  min_exclusive?: boolean;
  choices: string[];
  group: string;
  description: string;
  default: number | boolean | string;
}

export interface InitResult {
  version: string;
  schema: SettingSpec[];
  defaults: Record<string, number | boolean | string>;
}

export interface OpenResult {
  layers: number;
  info: JobInfo;
}

export interface GcodeParseResult {
  layers: number;
  dropletWidth: number;
  layerHeight: number;
  header: Record<string, string>;
}

export type Request =
  | { id: number; kind: "init"; data: null }
  | { id: number; kind: "open"; data: { stl: ArrayBuffer; name: string; settings: string } }
  | { id: number; kind: "slice"; data: { from: number; to: number; analyse?: boolean; gcode?: boolean } }
  | { id: number; kind: "preview"; data: { index: number; analyse?: boolean } }
  | { id: number; kind: "header"; data: { summary: string } }
  | { id: number; kind: "footer"; data: { summary: string } }
  | { id: number; kind: "repairs"; data: { summary: string } }
  | { id: number; kind: "parse_gcode"; data: { file: Blob } }
  | { id: number; kind: "crash"; data: null };

export type RequestKind = Request["kind"];

export type Reply =
  | { id: number; kind: "progress"; data: LayerData }
  | { id: number; kind: "result"; data: unknown }
  | { id: number; kind: "error"; data: { kind: string; message: string } };

/** Splits "kind: message" as produced by src/wasm.rs. */
export function splitError(text: string): { kind: string; message: string } {
  const m = /^(import|setting|nothing_to_print|io|internal): ([\s\S]*)$/.exec(text);
  return m ? { kind: m[1], message: m[2] } : { kind: "internal", message: text };
}

export function transferablesOf(layer: LayerData): Transferable[] {
  const out = [layer.droplets.buffer, layer.roles.buffer, layer.travel.buffer] as Transferable[];
  if (layer.mask) out.push(layer.mask.void.buffer, layer.mask.overfill.buffer);
  return out;
}

/** Adds every number of `b` into `a` (nested objects too): sums the layers' summaries
 *  without the page having to know the core's Summary fields. */
export function addNumbers(a: Record<string, unknown>, b: Record<string, unknown>): Record<string, unknown> {
  for (const [k, v] of Object.entries(b)) {
    if (typeof v === "number") a[k] = (typeof a[k] === "number" ? (a[k] as number) : 0) + v;
    else if (v && typeof v === "object" && !Array.isArray(v)) {
      const inner = a[k] && typeof a[k] === "object" ? (a[k] as Record<string, unknown>) : {};
      a[k] = addNumbers(inner, v as Record<string, unknown>);
    } else if (!(k in a)) a[k] = v;
  }
  return a;
}

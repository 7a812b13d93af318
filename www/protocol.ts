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

/** The mask from the core's flat arrays (src/wasm.rs: `mask_cell`, `mask_tiles` = origin x,
 *  origin y, width, height per tile, `void_mask` and `overfill_mask` = the tiles' shares one
 *  after the other); each tile gets its own buffers. */
export function coverageMaskOf(r: {
  mask_cell: number;
  mask_tiles: Float64Array;
  void_mask: Uint8Array;
  overfill_mask: Uint8Array;
}): CoverageMask {
  const frames = r.mask_tiles;
  const voids = r.void_mask;
  const overfill = r.overfill_mask;
  const tiles: MaskTile[] = [];
  let at = 0;
  for (let i = 0; i + 3 < frames.length; i += 4) {
    const [x, y, width, height] = [frames[i], frames[i + 1], frames[i + 2], frames[i + 3]];
    const end = at + width * height;
    const over = overfill.subarray(at, end);
    tiles.push({
      origin: [x, y],
      width,
      height,
      void: voids.slice(at, end),
      overfill: over.some((v) => v !== 0) ? over.slice() : new Uint8Array(0),
    });
    at = end;
  }
  return { cell: r.mask_cell, tiles };
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
  for (const t of layer.mask?.tiles ?? []) out.push(t.void.buffer, t.overfill.buffer);
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

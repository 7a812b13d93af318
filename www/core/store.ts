// The page's state: the build job (job.ts), the slice (its layers in a bounded cache, their analyses and
// figures), the layer shown, and the generation counter that retires the callbacks of a run
// that was replaced. No DOM here.

import type { JobFileRef } from "./client";
import type { RawSettings, Settings } from "./settings";
import { Figures } from "./figures";
import type { Job } from "./job";
import type { JobFile, JobInfo, LayerAnalysis, LayerCounts, LayerData, SliceUnit } from "./protocol";
import { unitsOf } from "./units";
import type { Bounds } from "./view";
import type { ShareState } from "./share";

/** Layer previews kept in the page (`?cache=MB`, 384 MB unless asked): beyond this, layers far
 *  from the one shown are dropped and re-planned by a worker when they are shown again. */
export function cacheBudgetBytes(query: URLSearchParams): number {
  return Math.min(4096, Math.max(1, Number(query.get("cache")) || 384)) * 2 ** 20;
}

/** What a slice was made of: the job's files and the job (to open it again in fresh workers,
 *  and to tell whether a new slice is of the same models). */
export interface SlicedJob {
  refs: JobFileRef[];
  file: JobFile;
  /** The files' SHA-256, in the order of `refs`. */
  sha256: string[];
}

/** A job waiting for its model files (a job file or a preview link without them): the parts,
 *  and per file the name and, from a link, the SHA-256 the dropped file must have. */
export interface PendingJob {
  source: "link" | "file";
  job: JobFile;
  files: { name: string; sha256?: string; file?: File }[];
  /** The link's state (layer, view, …) to show once the job is sliced. */
  link?: ShareState;
}

/** Grows `b` to hold the points `d` (x, y pairs). */
function growBox(b: Bounds, d: Float32Array): void {
  for (let i = 0; i < d.length; i += 2) {
    const x = d[i];
    const y = d[i + 1];
    if (x < b.minX) b.minX = x;
    if (x > b.maxX) b.maxX = x;
    if (y < b.minY) b.minY = y;
    if (y > b.maxY) b.maxY = y;
  }
}

/** Everything known about one slice (or one opened .gco file). */
export class Slice {
  layers = 0;
  /** The core's info of a slice; empty for a .gco file (the core did not prepare it). */
  info: Partial<JobInfo> = {};
  z: number[] = [];
  counts: (LayerCounts | undefined)[] = [];
  /** Units whose droplets some layer in so far has (the highest unit + 1). */
  private seenUnits = 1;
  travelMm: number[] = [];
  /** The core's print time per layer, s (slices only; the per-layer plot). */
  layerSeconds: number[] = [];
  /** The core's overhang area per layer, mm² (slices only). */
  unsupportedArea: number[] = [];
  /** The overhang overlay per layer (the core's `unsupported_droplets` of the cached layer and
   *  the one below), made when the overlay is on; dropped with the layer. */
  overhangs = new Map<number, Uint8Array>();
  /** G-code by runs of layers, keyed by the run's first layer. */
  gcode = new Map<number, { to: number; blob: Blob }>();
  cache = new Map<number, LayerData>();
  cacheBytes = 0;
  done = 0;
  complete = false;
  /** The droplets' box, of a slice without the core's bounds (a .gco file). */
  bbox: Bounds = { minX: Infinity, minY: Infinity, maxX: -Infinity, maxY: -Infinity };
  /** Droplets, travel, estimates, coverage, worst layer, repairs: the core's (figures.ts). */
  figures = new Figures();
  /** Void analysis per layer (when the slice or a later pass made it). */
  analysis: (LayerAnalysis | undefined)[] = [];
  /** When the file was chosen (performance.now()), and the seconds from then until every
   *  layer's G-code was ready (the figure of the benchmark). */
  startedAt = performance.now();
  seconds: number | null = null;
  /** The job's key (job.ts `Job.key`) the slice was made of. */
  key = "";
  /** An opened .gco file and its header (source "gco"), for the calibration (views/calibrate.ts);
   *  the settings its header names (typed, checked by the core), or why there are none, for
   *  the form (views/controls.ts). */
  gcodeFile: { file: Blob; header: Record<string, string>; settings: RawSettings | null; settingsError: string | null } | null = null;

  constructor(
    readonly source: "stl" | "gco",
    readonly name: string,
    public dropletWidth: number,
    public layerHeight: number,
    /** The form's settings the slice was made with (a .gco file's: the form's when opened). */
    readonly settings: Settings,
    readonly job: SlicedJob | null,
    /** Bytes of layers the cache keeps ([[cacheBudgetBytes]]). */
    readonly cacheBudget: number,
  ) {}

  /** The discharge units the slice shows (units.ts): its settings' `units` (a .gco file's
   *  header's, when it names them), and never fewer than the units its droplets name. */
  get unitCount(): number {
    const named = this.source === "gco" ? (this.gcodeFile?.settings ?? this.gcodeFile?.header ?? null) : this.settings;
    return Math.max(unitsOf(named), this.seenUnits);
  }

  open(layers: number, info: Partial<JobInfo>): void {
    this.layers = layers;
    this.info = info;
  }

  put(l: LayerData, current: number): void {
    if (this.counts[l.index] === undefined) {
      this.done++;
      this.counts[l.index] = l.counts;
      this.seenUnits = Math.max(this.seenUnits, l.counts.parts.length);
      this.z[l.index] = l.z;
      this.travelMm[l.index] = l.travelMm;
      if (l.seconds !== undefined) this.layerSeconds[l.index] = l.seconds;
      if (l.unsupportedArea !== undefined) this.unsupportedArea[l.index] = l.unsupportedArea;
      if (this.source === "gco") this.figures.addReadLayer(l);
      // the droplets' box stands in for the core's bounds, which a .gco file has not (a pass
      // over every droplet on the page's thread, not spent where the bounds are known)
      if (!this.info.bounds) growBox(this.bbox, l.droplets);
    }
    const a = l.analysis;
    if (a && this.analysis[l.index] === undefined) this.analysis[l.index] = a;
    const old = this.cache.get(l.index);
    if (!old || (l.mask && !old.mask)) {
      if (old) this.cacheBytes -= layerBytes(old);
      this.cache.set(l.index, l);
      this.cacheBytes += layerBytes(l);
    }
    if (this.source === "stl") this.evict(current);
  }

  /** A run of layers is complete: its G-code and its part of the summary. */
  addUnit(u: SliceUnit): void {
    if (u.gcode) this.gcode.set(u.from, { to: u.to, blob: u.gcode });
    this.figures.addUnit(u);
  }

  /** The G-code of every layer in order, or the first layer without any. */
  gcodeParts(): Blob[] | number {
    const parts: Blob[] = [];
    for (let i = 0; i < this.layers; ) {
      const u = this.gcode.get(i);
      if (!u) return i;
      parts.push(u.blob);
      i = u.to;
    }
    return parts;
  }

  private evict(current: number): void {
    if (this.cacheBytes <= this.cacheBudget) return;
    const far = [...this.cache.keys()].sort((a, b) => Math.abs(b - current) - Math.abs(a - current));
    for (const i of far) {
      if (this.cacheBytes <= this.cacheBudget * 0.8 || Math.abs(i - current) <= 1) break;
      const l = this.cache.get(i)!;
      this.cacheBytes -= layerBytes(l);
      this.cache.delete(i);
      this.overhangs.delete(i);
    }
  }

  get droplets(): number {
    return this.figures.droplets;
  }

  /** Layers with a void analysis (the core's count). */
  get analysed(): number {
    return this.figures.analysed;
  }

  /** What slicing repaired (the core's, once the slice is complete). */
  get repairs(): string[] {
    return this.complete ? this.figures.repairs : [];
  }
}

/** Bytes a cached layer holds (droplets, roles, travel and the void mask's tiles). */
function layerBytes(l: LayerData): number {
  let m = 0;
  for (const t of l.mask?.tiles ?? []) m += t.void.byteLength + t.overfill.byteLength;
  return l.droplets.byteLength + l.roles.byteLength + l.units.byteLength + l.travel.byteLength + m;
}

/** The page's state (one per page). */
export class Store {
  /** The build job (null before the first file, and while a .gco file is shown). */
  job: Job | null = null;
  slice: Slice | null = null;
  /** The layer shown. */
  current = 0;
  /** Bumped by every run (slice, analysis, G-code read) and by cancel: a callback of an older
   *  run finds it changed and does nothing. */
  generation = 0;
  busy = false;
  /** The user zoomed or panned (or a link set the view): a new slice of the same model keeps it. */
  viewTouched = false;
  /** A job (from a link or a job file) waiting for its model files. */
  pending: PendingJob | null = null;
  /** The job was edited (or a change undone or redone) since it was opened. Leaving the page
   *  asks first when the job is not the one kept in the browser (flows/persist.ts). */
  edited = false;
  /** Bumped by every layout request: only the latest answer is applied. */
  layoutSeq = 0;
  /** When the file being opened was chosen: a slice's time runs from there. */
  fileChosenAt: number | null = null;
  /** Layers being fetched from a worker (evicted, or wanted with their mask). */
  readonly previewRequests = new Set<number>();
  /** The redraw waiting while the workers run (flows/slice.ts whileBusy). */
  busyRedraw: { gen: number; update: () => void } | null = null;
  /** When the last of those redraws ran (performance.now()). */
  busyRedrawAt = -Infinity;

  constructor(readonly cacheBudget: number) {}

  /** A new, empty slice with this store's cache budget. */
  newSlice(source: "stl" | "gco", name: string, dropletWidth: number, layerHeight: number, settings: Settings, job: SlicedJob | null): Slice {
    return new Slice(source, name, dropletWidth, layerHeight, settings, job, this.cacheBudget);
  }
}

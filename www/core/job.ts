// The build job as the page holds it (docs/spec.md "Build jobs", docs/jobs.md): its files (each a
// File the job worker's `Models` holds under a unique name), its ordered parts (a file, or one
// 3MF item, with its own transform, place and copies) and the core's latest `Layout`. The page
// computes no placement of its own: every matrix and box comes from the core's layout. No DOM.

import type { JobFileRef } from "./client";
import type { JobFile, JobSchema, Layout, ModelInfo, PartSpec, SettingSpec } from "./protocol";
import { DEFAULTS, isPartKey, PART_KEYS, type PartKey, type RawSettings, type Settings, type SomeSettings } from "./settings";

/** The keys of a part (rotate_*, scale_*, place_*: the settings table's `part` rows,
 *  settings.gen.ts `PART_KEYS`). The core refuses them in a job's settings, so the settings
 *  form hides them and the page keeps them in each part's spec. */
export { PART_KEYS };

/** A job's settings: every setting but the part keys. */
export type JobSettings = Omit<Settings, PartKey>;

/** The settings the core takes for a job: `values` without the part keys (the one place the
 *  page drops them). */
export function jobSettings(values: Settings): JobSettings;
export function jobSettings(values: SomeSettings): Partial<JobSettings>;
export function jobSettings(values: SomeSettings): Partial<JobSettings> {
  const out: SomeSettings = { ...values };
  for (const k of PART_KEYS) delete out[k];
  return out;
}

/** The part keys among settings from outside (an older link's `rotate_z`, …), as a part's. */
export function partKeysOf(settings: RawSettings): Partial<Pick<PartSpec, PartKey>> {
  const out: Partial<Record<PartKey, number>> = {};
  for (const [k, v] of Object.entries(settings)) if (isPartKey(k) && typeof v === "number") out[k] = v;
  return out;
}

/** The core's range of a number of a part (the part keys, copies, unit: the core's
 *  `job_schema`); undefined for a key that is not one. */
export function partNumber(job: JobSchema, key: string): SettingSpec | undefined {
  return job.part_numbers.find((s) => s.name === key);
}

/** Whether `x` is a value the core takes for the part's number `spec`. */
export function fitsPart(spec: SettingSpec, x: number): boolean {
  const { min, max } = spec;
  if (!Number.isFinite(x) || min === null || max === null) return false;
  if (spec.kind === "integer" && !Number.isInteger(x)) return false;
  return (spec.min_exclusive ? x > min : x >= min) && x <= max;
}

const nf = new Intl.NumberFormat("en-US");

/** The range of a part's number in words: "a whole number 1 … 100", "> 0 and ≤ 1,000",
 *  "−360 … 360 deg". */
export function partRangeWords(spec: SettingSpec): string {
  const unit = spec.unit ? ` ${spec.unit}` : "";
  const [min, max] = [spec.min ?? -Infinity, spec.max ?? Infinity];
  const n = (x: number) => (x < 0 ? `−${nf.format(-x)}` : nf.format(x));
  if (spec.kind === "integer") return `a whole number ${n(min)} … ${n(max)}`;
  if (spec.min_exclusive) return `> ${n(min)} and ≤ ${n(max)}${unit}`;
  return `${n(min)} … ${n(max)}${unit}`;
}

/** A part's mirror flags (docs/jobs.md: along the plate's x, y, z after rotation and scale). */
export const MIRRORS = ["mirror_x", "mirror_y", "mirror_z"] as const;

/** The core's lay-flat angles (the face down after rotate x, then y) for a part mirrored along
 *  z or not: a z mirror after the rotation turns the face up, so the face is turned up first —
 *  a half turn about x before, Rx(180)·Ry(b)·Rx(a) = Ry(−b)·Rx(a + 180) — and the mirror puts
 *  it down. Angles stay in −360 … 360. */
export function layFlatAngles(a: { rotate_x: number; rotate_y: number }, mirrorZ: boolean): { rotate_x: number; rotate_y: number } {
  if (!mirrorZ) return { rotate_x: a.rotate_x, rotate_y: a.rotate_y };
  const x = a.rotate_x + 180;
  return { rotate_x: x > 360 ? x - 360 : x, rotate_y: a.rotate_y === 0 ? 0 : -a.rotate_y };
}

/** Triangles the 3D view draws for a whole job, shared by its instances. */
export const DISPLAY_BUDGET = 300_000;

/** A file of the job. */
export interface JobModel {
  /** Unique within the job ("gear.stl", "gear (2).stl"): the key in the worker's `Models`. */
  name: string;
  file: File;
  sha256: string;
  info: ModelInfo;
}

/** A display mesh of a part (decimated for drawing only) and the budget it was made with. */
export interface DisplayMesh {
  positions: Float32Array;
  budget: number;
}

/** The part keys a part always has (its place is both numbers or absent: arranged). */
type HeldKey = Exclude<PartKey, "place_x" | "place_y">;
const HELD_KEYS = PART_KEYS.filter((k): k is HeldKey => k !== "place_x" && k !== "place_y");

/** One part: a stable id (the 3D view's ids are `${id}:${copy}`), its file and its spec. Its
 *  display mesh is the job's (`Job.meshOf`), never the part's: undo snapshots keep parts, and
 *  a mesh in each would keep every mesh ever fetched (megabytes an edit). */
export interface Part {
  id: number;
  spec: Required<Pick<PartSpec, "file" | HeldKey | "mirror_x" | "mirror_y" | "mirror_z" | "copies" | "unit">> & {
    /** Absent, never null: the whole file, unplaced (arranged), the file's name. */
    [K in "item" | "place_x" | "place_y" | "name"]?: NonNullable<PartSpec[K]>;
  };
}

export type Spec = Part["spec"];

/** Changes of parts' specs: `place: null` clears a placement (the part is arranged). */
export type Changes = Partial<Omit<Spec, "file">> & { place?: null };

/** A spec with every default filled in (the core's defaults, docs/jobs.md). */
export function fullSpec(p: PartSpec): Spec {
  const s = { file: p.file } as Spec;
  for (const k of HELD_KEYS) s[k] = p[k] ?? DEFAULTS[k];
  s.mirror_x = p.mirror_x === true;
  s.mirror_y = p.mirror_y === true;
  s.mirror_z = p.mirror_z === true;
  s.copies = p.copies ?? 1;
  s.unit = p.unit ?? 0;
  if (p.item !== undefined && p.item !== null) s.item = p.item;
  if (typeof p.place_x === "number" && typeof p.place_y === "number" && Number.isFinite(p.place_x) && Number.isFinite(p.place_y)) {
    s.place_x = p.place_x;
    s.place_y = p.place_y;
  }
  if (p.name !== undefined) s.name = p.name;
  return s;
}

/** A part as a job file writes it: only what differs from the defaults (never NaN: a place
 *  is both numbers or absent). */
export function specOut(s: Spec): PartSpec {
  const out: PartSpec = { file: s.file };
  if (s.item !== undefined) out.item = s.item;
  for (const k of HELD_KEYS) if (s[k] !== DEFAULTS[k]) out[k] = s[k];
  for (const k of MIRRORS) if (s[k]) out[k] = true;
  if (s.place_x !== undefined && s.place_y !== undefined && Number.isFinite(s.place_x) && Number.isFinite(s.place_y)) {
    out.place_x = s.place_x;
    out.place_y = s.place_y;
  }
  if (s.copies !== 1) out.copies = s.copies;
  if (s.unit !== 0) out.unit = s.unit;
  if (s.name !== undefined) out.name = s.name;
  return out;
}

/** `name` made unique among `taken`: "gear.stl", "gear (2).stl", "gear (3).stl", … */
export function uniqueName(name: string, taken: (n: string) => boolean): string {
  if (!taken(name)) return name;
  const dot = name.lastIndexOf(".");
  const [stem, ext] = dot > 0 ? [name.slice(0, dot), name.slice(dot)] : [name, ""];
  for (let k = 2; ; k++) {
    const n = `${stem} (${k})${ext}`;
    if (!taken(n)) return n;
  }
}

export class Job {
  /** The files, in the order they were added. */
  readonly models = new Map<string, JobModel>();
  parts: Part[] = [];
  /** The core's layout of `parts` (null until the first answer). */
  layout: Layout | null = null;
  /** The part selected in the panel and the 3D view (an id). */
  selected: number | null = null;
  /** The display meshes, one per file and item ([[meshKey]]): shared by the parts and their
   *  copies, replaced when fetched again, dropped with their file. */
  readonly meshes = new Map<string, DisplayMesh>();
  private nextId = 0;

  /** A new part of `model` (ids count from 0 in each job). */
  newPart(spec: PartSpec): Part {
    return { id: this.nextId++, spec: fullSpec(spec) };
  }

  part(id: number | null): Part | undefined {
    return id === null ? undefined : this.parts.find((p) => p.id === id);
  }

  /** The job as the core reads it: `settings` and the parts (every default written out). */
  file(settings: Partial<JobSettings>, parts: Part[] = this.parts): JobFile {
    return { settings, parts: parts.map((p) => ({ ...p.spec })) };
  }

  /** The files the parts use, as the pool needs them. */
  refs(parts: Part[] = this.parts): JobFileRef[] {
    const used = new Set(parts.map((p) => p.spec.file));
    return [...this.models.values()].filter((m) => used.has(m.name)).map((m) => ({ name: m.name, file: m.file }));
  }

  /** Drops the files no part uses any more, and their meshes. */
  prune(): void {
    const used = new Set(this.parts.map((p) => p.spec.file));
    for (const n of [...this.models.keys()]) if (!used.has(n)) this.models.delete(n);
    const drawn = new Set(this.parts.map((p) => meshKey(p.spec)));
    for (const k of [...this.meshes.keys()]) if (!drawn.has(k)) this.meshes.delete(k);
  }

  /** The display mesh of part `p` (null: not fetched yet). */
  meshOf(p: Part): DisplayMesh | null {
    return this.meshes.get(meshKey(p.spec)) ?? null;
  }

  /** The job's name: its first file, "+ N more" for the others. */
  get name(): string {
    const files = [...new Set(this.parts.map((p) => p.spec.file))];
    if (files.length === 0) return "";
    return files.length === 1 ? files[0] : `${files[0]} + ${files.length - 1} more`;
  }

  /** Instances in all (copies of every part). */
  get instances(): number {
    return this.parts.reduce((n, p) => n + p.spec.copies, 0);
  }

  /** What the slice shown was made of: settings and parts (to tell when it is out of date). */
  key(settings: Partial<JobSettings>): string {
    return JSON.stringify({ settings, parts: this.parts.map((p) => p.spec), files: this.refs().map((r) => r.name) });
  }
}

/** The key of a part's display mesh: its file and item (parts of both share one mesh). */
export const meshKey = (s: Pick<Spec, "file" | "item">): string => `${s.file}\u0000${s.item ?? ""}`;

/** The display name of a part: its own, or its file's (with the 3MF item). */
export function partName(job: Job, p: Part): string {
  if (p.spec.name) return p.spec.name;
  const m = job.models.get(p.spec.file);
  if (p.spec.item !== undefined && m) return `${m.info.items[p.spec.item]?.name ?? `item ${p.spec.item}`} (${p.spec.file})`;
  return p.spec.file;
}

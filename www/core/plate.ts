// The plate as a rule: which instances of a layout reach past the plate (`plate_x` × `plate_y`,
// and above `plate_z` when the core has that setting), in plain words; and the core's job
// messages ("parts[2].scale_x: …") in the words the page shows ("Part 3, scale x: …"). No DOM.

import { partName, type Job } from "./job";
import type { Layout } from "./protocol";
import type { Value } from "./settings";

export interface Plate {
  x: number;
  y: number;
  /** The plate's height (null: the settings have none). */
  z: number | null;
}

/** An instance off the plate: its part (index in the job), its copy and the message. */
export interface OffPlate {
  part: number;
  copy: number;
  message: string;
}

/** Overshoots smaller than this (mm) are rounding, not a part off the plate. */
const TOLERANCE_MM = 1e-6;

const positive = (v: Value | undefined): number | null => (typeof v === "number" && Number.isFinite(v) && v > 0 ? v : null);

/** The plate of the settings `values` (null when its size is not a positive number). */
export function plateOf(values: Record<string, Value>): Plate | null {
  const x = positive(values.plate_x);
  const y = positive(values.plate_y);
  if (x === null || y === null) return null;
  return { x, y, z: positive(values.plate_z) };
}

const mm = (v: number) => (v < 0.1 ? "less than 0.1" : v.toFixed(1).replace(/\.0$/, ""));

/** The instances of `layout` that reach past `plate`, each with a message naming the part
 *  (`names[part]`: its display name) and how far, in plain words. */
export function offPlate(layout: Layout | null, plate: Plate | null, names: readonly string[]): OffPlate[] {
  if (!layout || !plate) return [];
  const out: OffPlate[] = [];
  for (const inst of layout.instances) {
    const sides: [number, string][] = [
      [-inst.min[0], "left edge"],
      [inst.max[0] - plate.x, "right edge"],
      [-inst.min[1], "front edge"],
      [inst.max[1] - plate.y, "back edge"],
    ];
    const [by, side] = sides.reduce((a, b) => (b[0] > a[0] ? b : a));
    const high = plate.z !== null ? inst.max[2] - plate.z : -Infinity;
    if (!(by > TOLERANCE_MM) && !(high > TOLERANCE_MM)) continue;
    const copy = inst.copies > 1 ? ` (copy ${inst.copy + 1})` : "";
    const who = `Part ${inst.part + 1} “${names[inst.part] ?? inst.name}”${copy}`;
    const message =
      by > TOLERANCE_MM
        ? `${who} reaches ${mm(by)} mm past the plate's ${side} — move it or press Arrange.`
        : `${who} is ${mm(high)} mm taller than the printer's height (plate z ${plate.z} mm) — scale it down or lay it flat.`;
    out.push({ part: inst.part, copy: inst.copy, message });
  }
  return out;
}

/** A message of the core about a job in the page's words: "bad job:" dropped, `parts[i].key`
 *  → "Part i+1, key words", `parts[i] (name)` → "Part i+1 “name”". */
export function plainJobMessage(message: string): string {
  return message
    .replace(/^bad job:\s*/i, "")
    .replace(/parts\[(\d+)\]\.([a-z_]+)/g, (_, i: string, key: string) => `Part ${Number(i) + 1}, ${key.replace(/_/g, " ")}`)
    .replace(/parts\[(\d+)\] \(([^()]*)\)/g, (_, i: string, name: string) => `Part ${Number(i) + 1} “${name}”`)
    .replace(/parts\[(\d+)\]/g, (_, i: string) => `Part ${Number(i) + 1}`);
}

/** The instances of the page's `job` off the plate of the settings `values`. */
export function jobOffPlate(job: Job | null, values: Record<string, Value> | undefined): OffPlate[] {
  if (!job || !values) return [];
  return offPlate(job.layout, plateOf(values), job.parts.map((p) => partName(job, p)));
}

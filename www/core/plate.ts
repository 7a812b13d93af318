// The plate rule as the core states it (docs/jobs.md "The plate rule"): the layout's misfits —
// instances larger than the plate, taller than the chamber or placed past an edge — each with
// the core's sentence and what fits (the turn about z, the scale); which of them block slicing
// (all, unless `allow_off_plate`, which never allows a chamber too low); and the core's job
// messages ("parts[2].scale_x: …") in the words the page shows ("Part 3, scale x: …"). No DOM.

import type { Job } from "./job";
import type { Layout, Misfit } from "./protocol";
import type { Settings } from "./settings";

/** An instance off the plate: its part (index in the job), its copy, the core's sentence, and
 *  what fits (`turn`: the part's rotate_z turned 90° about z; `scale`: the whole percent,
 *  `scaleTo` its scale_x/y/z). `blocks`: the job is not sliced while it is there. */
export interface OffPlate {
  part: number;
  copy: number;
  message: string;
  turn: number | null;
  scale: number | null;
  scaleTo: [number, number, number] | null;
  blocks: boolean;
}

const finite = (v: unknown): v is number => typeof v === "number" && Number.isFinite(v);

function offPlateOf(m: Misfit, allow: boolean): OffPlate {
  const to = m.scale_to;
  return {
    part: m.part,
    copy: m.copy,
    message: m.message,
    turn: finite(m.turn_rotate_z) ? m.turn_rotate_z : null,
    scale: finite(m.scale_percent) ? m.scale_percent : null,
    scaleTo: to && to.length === 3 && to.every(finite) ? [to[0], to[1], to[2]] : null,
    blocks: !(allow && m.kind !== "taller"),
  };
}

/** Every misfit of `layout` (`allow`: the settings' `allow_off_plate`). */
export function offPlate(layout: Layout | null, allow: boolean): OffPlate[] {
  return (layout?.misfits ?? []).map((m) => offPlateOf(m, allow));
}

/** Every misfit of the page's `job` with the settings `values`, blocking or not. */
export function jobMisfits(job: Job | null, values: Pick<Settings, "allow_off_plate"> | undefined): OffPlate[] {
  if (!job || !values) return [];
  return offPlate(job.layout, values.allow_off_plate === true);
}

/** The instances of the page's `job` off the plate that keep it from being sliced. */
export function jobOffPlate(job: Job | null, values: Pick<Settings, "allow_off_plate"> | undefined): OffPlate[] {
  return jobMisfits(job, values).filter((o) => o.blocks);
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

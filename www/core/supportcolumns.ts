// The support of a slice as boxes for the 3D view (views/view3d/support3d.ts draws them): the
// 3D view has no support geometry of its own, so every layer's support droplets (role 3), as
// they arrive from the workers, are binned to square cells and kept as runs of occupied cells
// per row; runs that repeat on consecutive layers become one column. Bounded: at most
// [[MAX_RUNS]] runs kept and [[MAX_BOXES]] boxes handed out; beyond either the cells double
// in size (the preview coarsens, the memory does not grow).

import type { LayerData } from "./protocol";

/** Runs (row, first cell, last cell) kept over all layers: 4 M Int32 triples ≈ 48 MB at most. */
export const MAX_RUNS = 4_000_000;
/** Boxes handed to the 3D view (instances of one box). */
export const MAX_BOXES = 200_000;
/** Role of a support droplet (core/protocol.ts `LayerData.roles`). */
const SUPPORT = 3;

/** Cell size for droplets of width `b` (mm): 2.5 B, at least 0.5 mm. */
export function cellFor(b: number): number {
  return Number.isFinite(b) && b > 0 ? Math.max(0.5, 2.5 * b) : 1;
}

export class SupportColumns {
  /** Per layer: (row, c0, c1) triples, rows ascending, runs within a row ascending. */
  private layers: (Int32Array | undefined)[] = [];
  private runs = 0;
  private boxes: Float32Array | null = null;

  constructor(
    /** Cell edge, mm (doubled when the bounds are reached). */
    public cell: number,
    /** Layer height, mm: layer i spans [i·h, (i + 1)·h]. */
    private readonly layerHeight: number,
  ) {}

  /** A layer as it arrived (a layer seen before is ignored). */
  add(l: LayerData): void {
    if (this.layers[l.index] !== undefined || !l.roles.includes(SUPPORT)) return;
    const cells: number[] = [];
    const d = l.droplets;
    for (let i = 0; i < l.roles.length; i++) {
      if (l.roles[i] !== SUPPORT) continue;
      const cx = Math.floor(d[2 * i] / this.cell);
      const cy = Math.floor(d[2 * i + 1] / this.cell);
      if (Math.abs(cx) < 1e6 && Math.abs(cy) < 1e6) cells.push(cy, cx);
    }
    const runs = runsOf(cells);
    this.layers[l.index] = runs;
    this.runs += runs.length / 3;
    this.boxes = null;
    while (this.runs > MAX_RUNS) this.coarsen();
  }

  /** Doubles the cell: every layer's runs re-binned. */
  private coarsen(): void {
    this.cell *= 2;
    this.runs = 0;
    this.layers = this.layers.map((r) => {
      if (!r) return r;
      const cells: number[] = [];
      for (let k = 0; k < r.length; k += 3) {
        const row = Math.floor(r[k] / 2);
        for (let c = Math.floor(r[k + 1] / 2); c <= Math.floor(r[k + 2] / 2); c++) cells.push(row, c);
      }
      const out = runsOf(cells);
      this.runs += out.length / 3;
      return out;
    });
    this.boxes = null;
  }

  /** The support as boxes x0, y0, z0, x1, y1, z1 (mm, plate coordinates): a run of cells
   *  repeated on consecutive layers is one box, its top 1 % of a layer below its last layer's
   *  top (the 3D view clips at a layer's top: a face right on the plane would flicker). At
   *  most [[MAX_BOXES]] (cells coarsened until they fit). Cached until a layer arrives. */
  columns(): Float32Array {
    if (this.boxes) return this.boxes;
    for (;;) {
      const out = this.merge();
      if (out.length / 6 <= MAX_BOXES) return (this.boxes = out);
      this.coarsen();
    }
  }

  private merge(): Float32Array {
    const out: number[] = [];
    const h = this.layerHeight;
    const c = this.cell;
    // open columns: run key → the layer it started on; continued while the next layer repeats it
    let open = new Map<string, number>();
    const close = (key: string, from: number, to: number) => {
      const [row, c0, c1] = key.split(",").map(Number);
      out.push(c0 * c, row * c, from * h, (c1 + 1) * c, (row + 1) * c, (to - 0.01) * h);
    };
    for (let i = 0; i <= this.layers.length; i++) {
      const r = this.layers[i];
      const next = new Map<string, number>();
      if (r) {
        for (let k = 0; k < r.length; k += 3) {
          const key = `${r[k]},${r[k + 1]},${r[k + 2]}`;
          next.set(key, open.get(key) ?? i);
          open.delete(key);
        }
      }
      for (const [key, from] of open) close(key, from, i);
      open = next;
    }
    return Float32Array.from(out);
  }
}

/** (row, col) pairs → runs (row, first col, last col), sorted. */
function runsOf(cells: number[]): Int32Array {
  const n = cells.length / 2;
  const order = Array.from({ length: n }, (_, i) => i).sort((a, b) => cells[2 * a] - cells[2 * b] || cells[2 * a + 1] - cells[2 * b + 1]);
  const out: number[] = [];
  for (const i of order) {
    const row = cells[2 * i];
    const col = cells[2 * i + 1];
    const last = out.length - 3;
    if (last >= 0 && out[last] === row && col <= out[last + 2] + 1) out[last + 2] = Math.max(out[last + 2], col);
    else out.push(row, col, col);
  }
  return Int32Array.from(out);
}

/** The support columns of each slice (dropped with the slice). */
const bySlice = new WeakMap<object, SupportColumns>();

/** Records a layer of `slice` (droplets of width `b`, layers `h` high). */
export function recordSupport(slice: object, l: LayerData, b: number, h: number): void {
  if (!(h > 0) || !l.roles.includes(SUPPORT)) return;
  let s = bySlice.get(slice);
  if (!s) {
    s = new SupportColumns(cellFor(b), h);
    bySlice.set(slice, s);
  }
  s.add(l);
}

/** The slice's support as boxes (null: no support droplet arrived). */
export function supportColumns(slice: object): Float32Array | null {
  return bySlice.get(slice)?.columns() ?? null;
}

// The vertical cut's line on the plate (mm): its checks, its length.

export type Pt = [number, number];
export interface Line {
  a: Pt;
  b: Pt;
}

/** The longest line accepted (mm), as the core's `MAX_CUT_LENGTH`. */
const MAX_LENGTH = 10_000;

/** A line within bounds, or null (ends not finite, no length, too long or too far away). */
export function checkLine(l: unknown): Line | null {
  const o = l as { a?: unknown; b?: unknown } | null;
  const pt = (p: unknown): Pt | null =>
    Array.isArray(p) && p.length === 2 && p.every((v) => typeof v === "number" && Number.isFinite(v) && Math.abs(v) < 1e5) ? [p[0], p[1]] : null;
  const a = pt(o?.a);
  const b = pt(o?.b);
  if (!a || !b) return null;
  const len = Math.hypot(b[0] - a[0], b[1] - a[1]);
  return len > 1e-3 && len <= MAX_LENGTH ? { a, b } : null;
}

export function lineLength(l: Line): number {
  return Math.hypot(l.b[0] - l.a[0], l.b[1] - l.a[1]);
}

/** Whether the line passes within `margin` of the box (Liang–Barsky clipping of the segment
 *  to the box grown by `margin`); an empty box (min > max) is never crossed. */
export function crossesBox(l: Line, box: { minX: number; minY: number; maxX: number; maxY: number }, margin: number): boolean {
  if (!(box.maxX >= box.minX && box.maxY >= box.minY)) return false;
  let t0 = 0;
  let t1 = 1;
  const d = [l.b[0] - l.a[0], l.b[1] - l.a[1]];
  const lo = [box.minX - margin - l.a[0], box.minY - margin - l.a[1]];
  const hi = [box.maxX + margin - l.a[0], box.maxY + margin - l.a[1]];
  for (let k = 0; k < 2; k++) {
    if (d[k] === 0) {
      if (lo[k] > 0 || hi[k] < 0) return false;
      continue;
    }
    let [ta, tb] = [lo[k] / d[k], hi[k] / d[k]];
    if (ta > tb) [ta, tb] = [tb, ta];
    t0 = Math.max(t0, ta);
    t1 = Math.min(t1, tb);
    if (t0 > t1) return false;
  }
  return true;
}

/** Where the line is, in words: "y = 12.40 mm" for a line along x (both ends at one y), "x =
 *  …" for one along y, else its ends and its angle to the x axis ("(1.00, 2.00) → (30.00,
 *  12.50) mm, 19.9°"). */
export function cutLabel(l: Line): string {
  const mm = (v: number) => (Object.is(Math.round(v * 100), -0) ? 0 : v).toFixed(2);
  if (Math.abs(l.a[1] - l.b[1]) < 1e-9) return `y = ${mm(l.a[1])} mm`;
  if (Math.abs(l.a[0] - l.b[0]) < 1e-9) return `x = ${mm(l.a[0])} mm`;
  const deg = (Math.atan2(l.b[1] - l.a[1], l.b[0] - l.a[0]) * 180) / Math.PI;
  return `(${mm(l.a[0])}, ${mm(l.a[1])}) → (${mm(l.b[0])}, ${mm(l.b[1])}) mm, ${deg.toFixed(1)}°`;
}

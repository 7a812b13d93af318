// The views' geometry, shared by the layer view, the vertical cut, the 3D view and the preview
// links: a view (zoom and centre) with its limits, a box on the plate, the cut's view and the
// 3D camera.

export interface View {
  /** CSS pixels per mm. */
  scale: number;
  /** mm at the canvas centre. */
  cx: number;
  cy: number;
}

/** The renderer's zoom limits (CSS pixels per mm) and the farthest the view's centre may be
 *  from the plate's origin (mm): a view outside them is brought inside, whatever set it (a
 *  link, a .gco file's bounds, the wheel or a drag), so no drawing loop can run away. */
export const MIN_SCALE = 0.05;
export const MAX_SCALE = 5000;
export const MAX_CENTRE_MM = 1e5;
const clamp = (x: number, lo: number, hi: number) => Math.min(hi, Math.max(lo, x));

/** `v` brought within the limits; a number that is not finite is replaced by `fallback`'s. */
export function clampView(v: View, fallback: View = { scale: 10, cx: 0, cy: 0 }): View {
  const scale = Number.isFinite(v.scale) && v.scale > 0 ? v.scale : fallback.scale;
  const cx = Number.isFinite(v.cx) ? v.cx : fallback.cx;
  const cy = Number.isFinite(v.cy) ? v.cy : fallback.cy;
  return {
    scale: clamp(scale, MIN_SCALE, MAX_SCALE),
    cx: clamp(cx, -MAX_CENTRE_MM, MAX_CENTRE_MM),
    cy: clamp(cy, -MAX_CENTRE_MM, MAX_CENTRE_MM),
  };
}

export interface Bounds {
  minX: number;
  minY: number;
  maxX: number;
  maxY: number;
}

/** The vertical cut's view: its zoom and centre along the line and in z. */
export interface CutView {
  /** CSS pixels per mm (both axes). */
  scale: number;
  /** mm along the line and z (mm) at the plot's centre. */
  ct: number;
  cz: number;
}

/** The 3D view's camera: where it is and what it looks at (plate mm). */
export type Camera3D = { position: [number, number, number]; target: [number, number, number] };

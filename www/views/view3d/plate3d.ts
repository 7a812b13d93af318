// The build plate of the 3D view: its top face, a 10 mm grid, its outline and an axis hint at
// the origin (three.js objects; the view owns and disposes them).

import {
  BufferGeometry,
  CanvasTexture,
  Float32BufferAttribute,
  FrontSide,
  Group,
  LineBasicMaterial,
  LineSegments,
  Mesh,
  MeshBasicMaterial,
  type Object3D,
  PlaneGeometry,
  Sprite,
  SpriteMaterial,
  SRGBColorSpace,
} from "three";

/** Beyond this many grid lines per axis, the grid is drawn every 10^k·10 mm. */
const GRID_LINES_MAX = 400;

/** The plate's colours (sRGB). */
export interface PlateColors {
  plate: number;
  grid: number;
  gridMajor: number;
  outline: number;
}

/** The objects of a plate [0, x] × [0, y] at z = 0 (mm), and the build chamber above it up to
 *  `z` (mm; 0: none) as a faint box: its four vertical edges and its top outline. */
export function plateObjects(x: number, y: number, colors: PlateColors, z = 0): Object3D[] {
  // the plate's top face, seen from above only (from below, the parts' bottoms show)
  const top = new Mesh(
    new PlaneGeometry(x, y),
    new MeshBasicMaterial({ color: colors.plate, side: FrontSide, polygonOffset: true, polygonOffsetFactor: 1, polygonOffsetUnits: 1 }),
  );
  top.position.set(x / 2, y / 2, 0);
  top.renderOrder = -2;

  let step = 10;
  while (Math.max(x, y) / step > GRID_LINES_MAX) step *= 10;
  const minor: number[] = [];
  const major: number[] = [];
  for (let gx = step; gx < x - 1e-9; gx += step) (Math.round(gx / step) % 5 === 0 ? major : minor).push(gx, 0, 0, gx, y, 0);
  for (let gy = step; gy < y - 1e-9; gy += step) (Math.round(gy / step) % 5 === 0 ? major : minor).push(0, gy, 0, x, gy, 0);
  const outline = lines([0, 0, 0, x, 0, 0, x, 0, 0, x, y, 0, x, y, 0, 0, y, 0, 0, y, 0, 0, 0, 0], colors.outline);

  // axis hint at the origin: x red, y green, with labels
  const len = Math.min(20, Math.max(5, Math.min(x, y) * 0.15));
  const axes = new Group();
  axes.add(lines([0, 0, 0, len, 0, 0], 0xe03131), lines([0, 0, 0, 0, len, 0], 0x2f9e44));
  axes.add(label("x", "#e03131", len + len * 0.25, 0, 0, len * 0.35), label("y", "#2f9e44", 0, len + len * 0.25, 0, len * 0.35));
  axes.position.z = 0.01;
  const objects = [top, lines(minor, colors.grid), lines(major, colors.gridMajor), outline, axes];
  if (z > 0) objects.push(chamber(x, y, z, colors.outline));
  return objects;
}

/** The chamber's box above the plate: faint lines that never hide a part. */
function chamber(x: number, y: number, z: number, color: number): LineSegments {
  const corners = [0, 0, x, 0, x, y, 0, y];
  const xyz: number[] = [];
  for (let i = 0; i < 8; i += 2) {
    const [ax, ay, bx, by] = [corners[i], corners[i + 1], corners[(i + 2) % 8], corners[(i + 3) % 8]];
    xyz.push(ax, ay, 0, ax, ay, z, ax, ay, z, bx, by, z);
  }
  const box = lines(xyz, color);
  const m = box.material as LineBasicMaterial;
  m.transparent = true;
  m.opacity = 0.3;
  m.depthWrite = false;
  box.name = "chamber";
  return box;
}

export function lines(xyz: number[], color: number): LineSegments {
  const g = new BufferGeometry();
  g.setAttribute("position", new Float32BufferAttribute(xyz, 3));
  return new LineSegments(g, new LineBasicMaterial({ color }));
}

/** A text label facing the camera, `size` mm tall, centred at (x, y, z). */
function label(text: string, color: string, x: number, y: number, z: number, size: number): Sprite {
  const c = document.createElement("canvas");
  c.width = c.height = 64;
  const g = c.getContext("2d")!;
  g.fillStyle = color;
  g.font = "600 48px system-ui, sans-serif";
  g.textAlign = "center";
  g.textBaseline = "middle";
  g.fillText(text, 32, 34);
  const tex = new CanvasTexture(c);
  tex.colorSpace = SRGBColorSpace;
  const s = new Sprite(new SpriteMaterial({ map: tex, transparent: true, depthWrite: false }));
  s.position.set(x, y, z);
  s.scale.set(size, size, 1);
  return s;
}

/** Frees the geometries, materials and textures of `o` and everything below it. */
export function disposeObject(o: Object3D): void {
  o.traverse((c) => {
    const m = c as Partial<Mesh>;
    m.geometry?.dispose();
    const mats = m.material === undefined ? [] : Array.isArray(m.material) ? m.material : [m.material];
    for (const mat of mats) {
      (mat as SpriteMaterial).map?.dispose();
      mat.dispose();
    }
  });
}


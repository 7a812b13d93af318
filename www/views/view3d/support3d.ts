// The support in the 3D view: the boxes of core/supportcolumns.ts (columns of support cells
// over runs of layers, plate coordinates, mm) as one instanced box mesh, in the layer view's
// support colour, clipped with the parts at the current layer's top. Not pickable. View3D
// (view3d.ts) holds the mesh through `setSupport`.

import { BoxGeometry, InstancedMesh, Matrix4, MeshStandardMaterial, type Plane, type Scene } from "three";

/** The layer view's support colour (canvas/render.ts, style.css `i.support`). */
export const SUPPORT_COLOR = 0x1098ad;

/** Replaces `old` (freed) by a mesh of `boxes` (x0, y0, z0, x1, y1, z1 each; null or empty:
 *  none) clipped by `clip`; returns the new mesh. Throws on boxes that are not finite or not
 *  whole sextuples. */
export function showSupport(scene: Scene, old: InstancedMesh | null, boxes: Float32Array | null, clip: Plane): InstancedMesh | null {
  if (old) {
    scene.remove(old);
    old.geometry.dispose();
    (old.material as MeshStandardMaterial).dispose();
    old.dispose();
  }
  if (!boxes || boxes.length === 0) return null;
  if (boxes.length % 6 !== 0) throw new Error(`support boxes: ${boxes.length} numbers, not 6 per box`);
  const n = boxes.length / 6;
  const geometry = new BoxGeometry(1, 1, 1).translate(0.5, 0.5, 0.5);
  // drawn in front of a part's face at the same height (support touches the face above it,
  // support_gap_z = 0): no z-fighting stripes
  const material = new MeshStandardMaterial({ color: SUPPORT_COLOR, roughness: 0.75, metalness: 0, clippingPlanes: [clip], polygonOffset: true, polygonOffsetFactor: -1, polygonOffsetUnits: -1 });
  const mesh = new InstancedMesh(geometry, material, n);
  const m = new Matrix4();
  for (let i = 0; i < n; i++) {
    const [x0, y0, z0, x1, y1, z1] = boxes.subarray(6 * i, 6 * i + 6);
    if (![x0, y0, z0, x1, y1, z1].every(Number.isFinite) || !(x1 > x0 && y1 > y0 && z1 > z0)) {
      geometry.dispose();
      material.dispose();
      mesh.dispose();
      throw new Error(`support box ${i}: not a finite box`);
    }
    mesh.setMatrixAt(i, m.makeScale(x1 - x0, y1 - y0, z1 - z0).setPosition(x0, y0, z0));
  }
  mesh.instanceMatrix.needsUpdate = true;
  mesh.computeBoundingSphere();
  mesh.raycast = () => {};
  scene.add(mesh);
  return mesh;
}

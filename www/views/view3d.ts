// The stage's 3D tab: the sliced model on the plate in 3D (../view3d.ts), cut at the layer the
// slider shows. The toggle "Layer | 3D" switches the stage between the layer canvas and this
// view; the View3D (a WebGL context) is made the first time the tab is opened. Today the page
// has one part: the prepared mesh the first worker returns, in plate coordinates.

import type { Page } from "../page";
import type { PreparedMesh } from "../protocol";
import type { Slice } from "../store";
import { View3D, type View3DPart, type View3DSlice } from "../view3d";
import { $ } from "./dom";

/** The one part of today's page. */
export const PART_ID = "part";

const IDENTITY = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1];

/** Non-indexed triangle corners (9 floats per facet) of an indexed mesh; every index is
 *  checked against the vertices (the arrays cross a worker boundary). */
export function trianglePositions(vertices: Float64Array, facets: Uint32Array): Float32Array {
  if (vertices.length % 3 !== 0 || facets.length % 3 !== 0) throw new Error("the prepared mesh is malformed: its arrays are not triples");
  const n = vertices.length / 3;
  const out = new Float32Array(facets.length * 3);
  for (let i = 0, o = 0; i < facets.length; i++, o += 3) {
    const v = facets[i];
    if (v >= n) throw new Error(`the prepared mesh is malformed: facet ${Math.floor(i / 3)} names vertex ${v} of ${n}`);
    out[o] = vertices[3 * v];
    out[o + 1] = vertices[3 * v + 1];
    out[o + 2] = vertices[3 * v + 2];
  }
  return out;
}

export class View3DPanel {
  private view: View3D | null = null;
  private parts: View3DPart[] = [];
  private plate = { x: 154, y: 134 };
  private slice: View3DSlice | null = null;
  /** The model shown, and the one the camera was last fitted to: a new model is framed once
   *  (slicing the same model again keeps the camera). */
  private model: unknown = null;
  private framed: unknown = null;
  active = false;

  constructor(private readonly container: HTMLElement) {}

  /** The part of slice `s` (its prepared mesh, in plate coordinates). */
  static part(s: Slice, prepared: PreparedMesh): View3DPart {
    return { id: PART_ID, name: s.name, positions: trianglePositions(prepared.vertices, prepared.facets), matrix: IDENTITY };
  }

  /** Shows what slice `s` has in 3D, cut at layer `current` (nothing for a .gco file). */
  sync(s: Slice | null, current: number): void {
    const part = s?.source === "stl" ? s.part3d : null;
    this.parts = part ? [part] : [];
    this.model = part ? (s?.model ?? part) : null;
    const px = Number(s?.settings.plate_x);
    const py = Number(s?.settings.plate_y);
    if (px > 0 && py > 0 && Number.isFinite(px + py)) this.plate = { x: px, y: py };
    this.slice = part && s && s.layers > 0 && s.layerHeight > 0 ? { layerHeight: s.layerHeight, layers: s.layers, current } : null;
    this.apply();
  }

  private apply(): void {
    const v = this.view;
    if (!v) return;
    v.setPlate(this.plate.x, this.plate.y);
    v.setParts(this.parts);
    v.setSlice(this.slice);
    if (this.model !== null && this.model !== this.framed) {
      this.framed = this.model;
      v.fit();
    }
    $("view3d-empty").hidden = this.parts.length > 0;
  }

  /** Layer canvas or 3D view. */
  setActive(on: boolean): void {
    this.active = on;
    $("canvas-wrap").dataset.mode = on ? "3d" : "layer";
    $("mode-layer").setAttribute("aria-pressed", String(!on));
    $("mode-3d").setAttribute("aria-pressed", String(on));
    this.container.hidden = !on;
    if (on && !this.view) {
      this.view = new View3D(this.container);
      this.view.onSelect(() => {
        // today's page only tints the part; the parts panel will listen here
      });
      this.apply();
    }
  }

  fit(): void {
    this.view?.fit();
  }

  /** For the tests: the view's state and a synchronous draw (null before the tab was opened). */
  testState(): ReturnType<View3D["state"]> | null {
    this.view?.renderNow();
    return this.view?.state() ?? null;
  }
}

/** The toggle's buttons and the 3D view's double-click fit. */
export function wireView3D(page: Page): void {
  $("mode-layer").addEventListener("click", () => page.view3d.setActive(false));
  $("mode-3d").addEventListener("click", () => page.view3d.setActive(true));
  $("view3d").addEventListener("dblclick", () => page.view3d.fit());
}

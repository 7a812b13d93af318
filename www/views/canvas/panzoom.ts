// The 2D canvases that zoom and pan: the layer view (render.ts) and the vertical cut
// (cutrender.ts). One true scale for both axes (x to the right, y up); the backing store sized
// to device pixels (hidpi.ts); the view kept within core/view.ts' limits; mm ↔ CSS px; zoom
// about a point, pan, redraws on the next frame; and the pointer wiring (wheel zoom, drag pan,
// double-click fit) both canvases share.

import { clampView, MAX_SCALE, MIN_SCALE, type View } from "../../core/view";
import type { PanZoom } from "../page";
import { sizeCanvas, watchCanvas } from "./hidpi";

export abstract class PanZoomCanvas {
  private _view: View = { scale: 10, cx: 0, cy: 0 };
  /** The view, always within the limits (see `clampView`): set it as a whole. */
  get view(): View {
    return this._view;
  }
  set view(v: View) {
    this._view = clampView(v, this._view);
  }
  /** The user zoomed or panned (the cut then keeps its view when the canvas is resized). */
  touched = false;
  protected cssW = 1;
  protected cssH = 1;
  protected dpr = 1;
  private frame = 0;
  /** The canvas' box (or the pixel ratio) changed since the backing store was sized. */
  private stale = true;

  constructor(readonly canvas: HTMLCanvasElement) {
    // Sized and drawn in the next frame, not in the observer's callback: that runs inside the
    // frame whose layout moved the canvas (its style, layout, paint and commit), and a draw
    // there made that frame the page's longest task while slicing (a banner shown as a file
    // is chosen). Meanwhile the browser shows the last picture scaled to the new box.
    watchCanvas(canvas, () => {
      this.stale = true;
      this.request();
    });
  }

  /** Sizes the backing store, then draws. A subclass calls it at the end of its constructor
   *  (its own fields are set only after this class' constructor). */
  protected resize(): void {
    this.sizeStore();
    this.frameDraw();
  }

  /** Sizes the backing store when the box changed since; whether it did (setting it clears
   *  the canvas). */
  private sizeStore(): boolean {
    if (!this.stale) return false;
    this.stale = false;
    ({ cssW: this.cssW, cssH: this.cssH, dpr: this.dpr } = sizeCanvas(this.canvas));
    this.resized();
    return true;
  }

  /** Sizes the backing store when the box changed since, asking for a draw when it did.
   *  Whatever reads the size (and does not draw at once) calls it first. */
  protected sized(): void {
    if (this.sizeStore()) this.request();
  }

  /** Draws now (synchronously), sized first: the tests' hook. */
  drawNow(): void {
    this.sizeStore();
    this.draw();
  }

  /** A draw for the next frame (a resize, a request): by default `draw()`; a subclass may
   *  spread a costly picture over several frames (calling `request()` for the rest). */
  protected frameDraw(): void {
    this.draw();
  }

  /** Called after a resize, before the draw. */
  protected resized(): void {}

  abstract draw(): void;

  /** Where the view's centre is drawn, in CSS px: the canvas' centre (margins move it). */
  protected centre(): [number, number] {
    return [this.cssW / 2, this.cssH / 2];
  }

  /** Schedules a redraw on the next animation frame. */
  request(): void {
    if (this.frame) return;
    this.frame = requestAnimationFrame(() => {
      this.frame = 0;
      this.sizeStore();
      this.frameDraw();
    });
  }

  /** Zooms by `factor` keeping the mm under the CSS pixel (px, py) in place. */
  zoomAt(px: number, py: number, factor: number): void {
    this.sized();
    const [mx, my] = this.toMm(px, py);
    const scale = Math.min(MAX_SCALE, Math.max(MIN_SCALE, this.view.scale * factor));
    if (!Number.isFinite(scale)) return;
    const [ox, oy] = this.centre();
    this.touched = true;
    this.view = { scale, cx: mx - (px - ox) / scale, cy: my + (py - oy) / scale };
    this.request();
  }

  panBy(dxPx: number, dyPx: number): void {
    const v = this.view;
    this.touched = true;
    this.view = { scale: v.scale, cx: v.cx - dxPx / v.scale, cy: v.cy + dyPx / v.scale };
    this.request();
  }

  /** mm of the CSS pixel (px, py). */
  toMm(px: number, py: number): [number, number] {
    this.sized();
    const [ox, oy] = this.centre();
    const v = this.view;
    return [v.cx + (px - ox) / v.scale, v.cy - (py - oy) / v.scale];
  }

  /** CSS pixels of the point (x, y) in mm (the inverse of `toMm`). */
  toPx(x: number, y: number): [number, number] {
    this.sized();
    const [ox, oy] = this.centre();
    const v = this.view;
    return [(x - v.cx) * v.scale + ox, -(y - v.cy) * v.scale + oy];
  }
}

/** Wheel zoom about the pointer, drag pan and double-click `fit` on `target`'s canvas;
 *  `moved` after each zoom or pan step. A pointer that an earlier (capturing) listener took
 *  never reaches the pan. */
export function wirePanZoom(target: PanZoom, fit: () => void, moved: () => void = () => {}): void {
  const canvas = target.canvas;
  canvas.addEventListener(
    "wheel",
    (ev) => {
      ev.preventDefault();
      const r = canvas.getBoundingClientRect();
      const dy = ev.deltaMode === 1 ? ev.deltaY * 16 : ev.deltaY;
      target.zoomAt(ev.clientX - r.left, ev.clientY - r.top, Math.exp(-dy * 0.0015));
      moved();
    },
    { passive: false },
  );
  let drag: { x: number; y: number; id: number } | null = null;
  canvas.addEventListener("pointerdown", (ev) => {
    drag = { x: ev.clientX, y: ev.clientY, id: ev.pointerId };
    canvas.setPointerCapture(ev.pointerId);
    canvas.classList.add("dragging");
    // keys go to the canvas (the layer view's arrows); a canvas without a tabindex ignores it
    canvas.focus();
  });
  canvas.addEventListener("pointermove", (ev) => {
    if (!drag || ev.pointerId !== drag.id) return;
    target.panBy(ev.clientX - drag.x, ev.clientY - drag.y);
    drag.x = ev.clientX;
    drag.y = ev.clientY;
    moved();
  });
  const end = () => {
    drag = null;
    canvas.classList.remove("dragging");
  };
  canvas.addEventListener("pointerup", end);
  canvas.addEventListener("pointercancel", end);
  canvas.addEventListener("dblclick", fit);
}

// Draws the vertical cut (views/cut.ts, flows/cut.ts): distance along the cut line (mm, to
// the right) × z (mm, up), one true scale for both. Per layer: the part's section along the
// line (light), the droplets the plane crosses, each as the chord of its footprint disc at the
// plane (width 2·√(R² − d²) for a droplet at distance d from the plane, R = D/2 of the
// analysis' footprint) over the layer's height H, coloured by role; the 3D estimate's voids
// (the core's intervals, at 6 heights per slab) over them; the current layer outlined. Only
// layers and droplets in view are drawn, batched into one Path2D per colour.

import type { CutView } from "../../core/view";
import type { CutCanvas, CutLayer } from "../page";
import { PanZoomCanvas } from "./panzoom";
import { CLASS_COLORS, CLASS_ORDER, drawTag, dropletClass, VOID_RGB } from "./render";

/** Colour of a droplet of the cut by its role and discharge unit (render.ts `dropletClass`:
 *  the support and the parts of each unit but unit 0 have colours of their own). */
export function cutColor(role: number, unit = 0): string {
  return CLASS_COLORS[dropletClass(role, unit)];
}

const SECTION_COLOR = "#e3e8ef";
const CURRENT_COLOR = "#1c2430";
const AXIS_COLOR = "#495057";
const MARGIN_LEFT = 54;
const MARGIN_BOTTOM = 30;

export class CutRenderer extends PanZoomCanvas implements CutCanvas {
  layers = new Map<number, CutLayer>();
  /** Top z of each layer (mm), as the slice gives them. */
  z: number[] = [];
  layerHeight = 0.1;
  /** Footprint radius R (mm) for the chords. */
  radius = 0.104;
  length = 0;
  current = -1;
  showVoids = true;

  constructor(canvas: HTMLCanvasElement) {
    super(canvas);
    this.resize();
  }

  /** A resize keeps the view the user zoomed or panned to, else it fits the cut again. */
  protected resized(): void {
    if (!this.touched) this.fit();
  }

  /** The view as mm along the line (`ct`) and z (`cz`) at the plot's centre. */
  cutView(): CutView {
    const v = this.view;
    return { scale: v.scale, ct: v.cx, cz: v.cy };
  }

  /** Sets the view, brought within the layer view's limits. */
  setView(v: CutView): void {
    this.touched = true;
    this.view = { scale: v.scale, cx: v.ct, cy: v.cz };
  }

  /** The plot area's centre in CSS px (the axes take the left and bottom margins). */
  protected centre(): [number, number] {
    return [MARGIN_LEFT + (this.cssW - MARGIN_LEFT) / 2, (this.cssH - MARGIN_BOTTOM) / 2];
  }

  /** The whole line × the part's height in view. */
  fit(): void {
    const top = this.z.reduce((m, z) => (z > m ? z : m), 0);
    if (!(this.length > 0) || !(top > 0)) return;
    this.sized();
    const w = this.cssW - MARGIN_LEFT - 24;
    const h = this.cssH - MARGIN_BOTTOM - 24;
    this.setView({ scale: Math.min(w / this.length, h / top), ct: this.length / 2, cz: top / 2 });
    this.touched = false;
    this.request();
  }

  draw(): void {
    const ctx = this.canvas.getContext("2d", { alpha: false });
    if (!ctx) return;
    const W = this.canvas.width;
    const H = this.canvas.height;
    const dpr = this.dpr;
    ctx.setTransform(1, 0, 0, 1, 0, 0);
    ctx.fillStyle = "#fbfcfd";
    ctx.fillRect(0, 0, W, H);
    const k = this.view.scale * dpr; // device px per mm
    const [ox, oy] = this.centre();
    const X = ox * dpr - this.view.cx * k; // device x of t = 0
    const Y = oy * dpr + this.view.cy * k; // device y of z = 0
    // visible ranges (mm)
    const t0 = this.view.cx - (ox - MARGIN_LEFT) / this.view.scale - this.radius;
    const t1 = this.view.cx + (this.cssW - ox) / this.view.scale + this.radius;
    const zLo = this.view.cy - (this.cssH - oy) / this.view.scale;
    const zHi = this.view.cy + oy / this.view.scale;
    const h = this.layerHeight;
    const plotLeft = MARGIN_LEFT * dpr;
    const plotBottom = H - MARGIN_BOTTOM * dpr;
    ctx.save();
    ctx.beginPath();
    ctx.rect(plotLeft, 0, W - plotLeft, plotBottom);
    ctx.clip();
    this.drawGrid(ctx, X, Y, k, plotLeft, plotBottom);
    // mm -> device px: x' = X + t k, y' = Y − z k
    ctx.setTransform(k, 0, 0, -k, X, Y);
    const section = new Path2D();
    // per colour class (render.ts `dropletClass`: near's third value)
    const roles = CLASS_COLORS.map(() => new Path2D());
    const voids = new Path2D();
    const r2 = this.radius * this.radius;
    // a hairline gap between droplets once they are a few pixels wide
    const gap = 0.6 / k;
    for (const [i, layer] of this.layers) {
      const top = this.z[i];
      if (top === undefined || top < zLo || top - h > zHi) continue;
      const bottom = top - h;
      const sp = layer.spans;
      if (sp) for (let j = 0; j + 1 < sp.length; j += 2) if (sp[j + 1] > t0 && sp[j] < t1) section.rect(sp[j], bottom, sp[j + 1] - sp[j], h);
      const n = layer.near;
      const inset = h * k > 5 ? gap : 0;
      for (let j = 0; j + 2 < n.length; j += 3) {
        const t = n[j];
        if (t < t0 || t > t1) continue;
        const w2 = r2 - n[j + 1] * n[j + 1];
        if (w2 <= 0) continue;
        const w = Math.sqrt(w2);
        const g = 2 * w * k > 5 ? gap : 0;
        roles[Math.min(CLASS_COLORS.length - 1, Math.max(0, n[j + 2]))].rect(t - w + g, bottom + inset, 2 * (w - g), h - 2 * inset);
      }
      const v = layer.voids;
      if (v && this.showVoids) {
        const band = h / 6;
        for (let j = 0; j + 2 < v.length; j += 3) {
          if (v[j + 2] < t0 || v[j + 1] > t1) continue;
          // true width: zoomed out, thin voids only tint the section (as much as they are)
          voids.rect(v[j + 1], bottom + v[j] * band, v[j + 2] - v[j + 1], band);
        }
      }
    }
    ctx.fillStyle = SECTION_COLOR;
    ctx.fill(section);
    for (const cls of CLASS_ORDER) {
      ctx.fillStyle = CLASS_COLORS[cls];
      ctx.fill(roles[cls]);
    }
    ctx.fillStyle = `rgba(${VOID_RGB.join(", ")}, 0.9)`;
    ctx.fill(voids);
    // the current layer
    const cur = this.z[this.current];
    ctx.setTransform(1, 0, 0, 1, 0, 0);
    if (cur !== undefined) {
      const yTop = Y - cur * k;
      const yBot = Y - (cur - h) * k;
      const pad = Math.max(0, (3 * dpr - (yBot - yTop)) / 2);
      ctx.fillStyle = "rgba(28, 36, 48, 0.07)";
      ctx.fillRect(plotLeft, yTop - pad, W - plotLeft, yBot - yTop + 2 * pad);
      ctx.strokeStyle = CURRENT_COLOR;
      ctx.lineWidth = 1.2 * dpr;
      ctx.setLineDash([6 * dpr, 4 * dpr]);
      ctx.beginPath();
      ctx.moveTo(plotLeft, Math.round(yTop - pad) + 0.5);
      ctx.lineTo(W, Math.round(yTop - pad) + 0.5);
      ctx.moveTo(plotLeft, Math.round(yBot + pad) - 0.5);
      ctx.lineTo(W, Math.round(yBot + pad) - 0.5);
      ctx.stroke();
      ctx.setLineDash([]);
    }
    ctx.restore();
    ctx.setTransform(1, 0, 0, 1, 0, 0);
    this.drawAxes(ctx, X, Y, k, plotLeft, plotBottom, cur);
  }

  private step(): number {
    const target = 70 / this.view.scale;
    const p = Math.pow(10, Math.floor(Math.log10(target)));
    for (const m of [1, 2, 5, 10]) if (m * p >= target) return m * p;
    return 10 * p;
  }

  /** Tick positions (mm) of one axis within [lo, hi]: at most 200. */
  private ticks(lo: number, hi: number): number[] {
    const step = this.step();
    const first = Math.ceil(lo / step);
    const count = Math.min(200, Math.floor(hi / step) - first + 1);
    const out: number[] = [];
    for (let i = 0; i < count; i++) out.push(+((first + i) * step).toPrecision(10));
    return out;
  }

  private drawGrid(ctx: CanvasRenderingContext2D, X: number, Y: number, k: number, left: number, bottom: number): void {
    const W = this.canvas.width;
    const p = new Path2D();
    for (const t of this.ticks((left - X) / k, (W - X) / k)) {
      const x = Math.round(X + t * k) + 0.5;
      p.moveTo(x, 0);
      p.lineTo(x, bottom);
    }
    for (const z of this.ticks((Y - bottom) / k, Y / k)) {
      const y = Math.round(Y - z * k) + 0.5;
      p.moveTo(left, y);
      p.lineTo(W, y);
    }
    ctx.strokeStyle = "#edf0f4";
    ctx.lineWidth = 1;
    ctx.stroke(p);
  }

  private drawAxes(ctx: CanvasRenderingContext2D, X: number, Y: number, k: number, left: number, bottom: number, cur: number | undefined): void {
    const W = this.canvas.width;
    const H = this.canvas.height;
    const dpr = this.dpr;
    ctx.fillStyle = "#fff";
    ctx.fillRect(0, 0, left, H);
    ctx.fillRect(0, bottom, W, H - bottom);
    ctx.strokeStyle = "#c9ced8";
    ctx.lineWidth = 1;
    ctx.beginPath();
    ctx.moveTo(left + 0.5, 0);
    ctx.lineTo(left + 0.5, bottom + 0.5);
    ctx.lineTo(W, bottom + 0.5);
    ctx.stroke();
    ctx.font = `${11 * dpr}px system-ui, sans-serif`;
    ctx.fillStyle = AXIS_COLOR;
    ctx.textAlign = "center";
    ctx.textBaseline = "top";
    for (const t of this.ticks((left - X) / k, (W - X) / k)) {
      const x = X + t * k;
      if (x < left + 12 * dpr) continue;
      ctx.fillText(String(t), x, bottom + 5 * dpr);
    }
    ctx.textAlign = "right";
    ctx.textBaseline = "middle";
    for (const z of this.ticks((Y - bottom) / k, Y / k)) {
      const y = Y - z * k;
      if (y > bottom - 6 * dpr) continue;
      ctx.fillText(String(z), left - 6 * dpr, y);
    }
    ctx.textAlign = "left";
    ctx.textBaseline = "top";
    ctx.fillText("mm along the cut", left + 8 * dpr, bottom + 17 * dpr);
    ctx.save();
    ctx.translate(12 * dpr, bottom / 2);
    ctx.rotate(-Math.PI / 2);
    ctx.textAlign = "center";
    ctx.fillText("z mm", 0, -6 * dpr);
    ctx.restore();
    if (cur !== undefined) {
      const y = Y - (cur - this.layerHeight / 2) * k;
      if (y > 0 && y < bottom) {
        const label = `Layer ${this.current + 1}`;
        drawTag(ctx, label, { size: 11.5 * dpr, pad: 5 * dpr, height: 18 * dpr, radius: 4 * dpr, color: CURRENT_COLOR }, (tw, th) => [
          W - tw - 8 * dpr,
          Math.min(Math.max(y - th - 4 * dpr, 4 * dpr), bottom - th - 4 * dpr),
        ]);
      }
    }
  }
}

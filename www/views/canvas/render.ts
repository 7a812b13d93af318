// Draws one layer on a 2D canvas: every droplet a disc of diameter B coloured by role, the
// layer below faintly, travel moves on demand, a millimetre grid and a scale bar.
// Discs up to STAMP_MAX device pixels wide are stamped into a pixel buffer (discs.ts: a few ms
// where Canvas paths cost the page's thread 150–300 ms on a 25,000-droplet layer). Zoomed in
// further, droplets are batched by role into one Path2D per colour (one fill call each) and
// droplets outside the view are skipped. Zoomed out on a big layer (a disc at most 3 device
// pixels wide, over 60,000 droplets), droplets are written straight into a pixel buffer as
// small squares: ~330,000 droplets then take ~10 ms instead of ~100 ms of path filling.

import type { CoverageMask, LayerData } from "../../core/protocol";
import type { Bounds } from "../../core/view";
import type { LayerCanvas } from "../page";
import { DiscBuffer, DiscStamps, rgb } from "./discs";
import { PanZoomCanvas } from "./panzoom";
import { UNIT_COLORS } from "../../core/units";

export const ROLE_COLORS = ["#d9480f", "#f59f00", "#3b8fdd"] as const;
export const ROLE_NAMES = ["Outer loop", "Inner loops", "Fill"] as const;
/** Support droplets (role 3, printed by the unit of `support = unitN`). */
export const SUPPORT_COLOR = "#1098ad";
/** A droplet's colour class: 0–2 its role (unit 0), 3 support, 3 + u a droplet of unit u's
 *  parts for u = 1 … 3 (core/units.ts `UNIT_COLORS`; in a .gco file, any droplet after `Tu`). */
export const CLASS_COLORS = [...ROLE_COLORS, SUPPORT_COLOR, ...UNIT_COLORS.slice(1)] as const;
export function dropletClass(role: number, unit: number): number {
  if (role === 3) return 3;
  if (unit >= 1) return 3 + Math.min(unit, CLASS_COLORS.length - 4);
  return Math.min(2, Math.max(0, role));
}
/** Drawn first to last: support at the bottom, the other units' parts, unit 0's fill, inner
 *  loops, the outer loop on top. */
export const CLASS_ORDER = [3, 6, 5, 4, 2, 1, 0] as const;
/** The overhang overlay: droplets without a droplet of the layer below within the rule. */
export const OVERHANG_COLOR = "#e8107a";
const BELOW_COLOR = "#dde2ea";
/** Largest droplet, in device pixels, drawn as a square of pixels rather than a disc. */
const PIXEL_MODE_MAX = 3;
/** Below this many droplets, discs are cheap enough at any zoom (and look smoother). */
const PIXEL_MODE_MIN_DROPLETS = 60_000;
/** Largest droplet, in device pixels, stamped into a pixel buffer rather than filled as a path
 *  (wider, few droplets fit on the screen and paths are cheap enough). */
const STAMP_MAX = 24;
/** Time a frame's draw spends stamping droplets (ms); the rest is stamped in the next frames. */
const FRAME_BUDGET_MS = 8;
/** The overhang overlay's disc, in droplet widths. */
const OVERHANG_DIAMETER = 1.24;

/** "#rrggbb" as a little-endian RGBA pixel. */
function pixel(hex: string): number {
  const v = parseInt(hex.slice(1), 16);
  return (0xff000000 | ((v & 0xff) << 16) | (v & 0xff00) | ((v >> 16) & 0xff)) >>> 0;
}
const TRAVEL_COLOR = "rgba(60, 60, 70, 0.55)";
/** Void overlay: uncovered part area (RGB, the largest opacity), overfill, the marker. */
export const VOID_RGB = [214, 51, 132] as const;
export const OVERFILL_RGB = [12, 166, 120] as const;
const VOID_ALPHA = 0.9;
const VOID_MARK = "#a61e4d";

/** At most this many grid lines per direction are drawn, whatever the view. */
const MAX_GRID_LINES = 2000;

/** A label on a white rounded box (device px): `place` puts the box of width `tw` and height
 *  `th` (its top-left corner). */
export function drawTag(
  ctx: CanvasRenderingContext2D,
  label: string,
  style: { size: number; pad: number; height: number; radius: number; color: string },
  place: (tw: number, th: number) => [number, number],
): void {
  ctx.font = `600 ${style.size}px system-ui, sans-serif`;
  const tw = ctx.measureText(label).width + 2 * style.pad;
  const th = style.height;
  const [lx, ly] = place(tw, th);
  ctx.fillStyle = "rgba(255, 255, 255, 0.92)";
  ctx.beginPath();
  ctx.roundRect(lx, ly, tw, th, style.radius);
  ctx.fill();
  ctx.fillStyle = style.color;
  ctx.textBaseline = "middle";
  ctx.fillText(label, lx + style.pad, ly + th / 2);
}

/** One colour of the stamping: discs of `stamps` at `at` (device px) whose `pick` is `want`. */
interface StampPass {
  stamps: DiscStamps;
  color: [number, number, number];
  at: Float64Array;
  count: number;
  pick: Uint8Array | null;
  want: number;
}

/** A resumable piece of a picture painted into the pixel buffer (a stamping pass, a square
 *  painting step): `run(from, deadline)` works from item `from` on until `deadline` and
 *  returns the item to go on from (`count`: done). */
interface Step {
  count: number;
  run: (from: number, deadline: number) => number;
}

/** Whether a loop at item `i` (begun at `from`) has used its time. */
const late = (i: number, from: number, deadline: number) => (i & 4095) === 0 && i > from && performance.now() > deadline;

export class Renderer extends PanZoomCanvas implements LayerCanvas {
  current: LayerData | null = null;
  below: LayerData | null = null;
  dropletWidth = 0.208;
  showTravel = false;
  showBelow = true;
  /** The void overlay of the current layer (when it carries a coverage mask). */
  showVoids = false;
  /** The overhang overlay: per droplet of `current`, 1 when it is unsupported (the core's
   *  `unsupported_droplets`); null while unknown or off. */
  overhangs: Uint8Array | null = null;
  /** Whether the overhang overlay is on (the page fetches `overhangs` for each layer). */
  showOverhangs = false;
  /** Called after every draw (for the zoom read-out). */
  onDraw: (() => void) | null = null;

  constructor(canvas: HTMLCanvasElement) {
    super(canvas);
    this.resize();
  }

  fit(b: Bounds | null): void {
    if (!b || !(b.maxX > b.minX) || !(b.maxY > b.minY)) return;
    this.sized();
    const margin = 28;
    const sx = (this.cssW - 2 * margin) / (b.maxX - b.minX);
    const sy = (this.cssH - 2 * margin) / (b.maxY - b.minY);
    // the setter keeps the zoom and the centre within the limits (a .gco's bounds may be huge)
    this.view = { scale: Math.min(sx, sy), cx: b.minX / 2 + b.maxX / 2, cy: b.minY / 2 + b.maxY / 2 };
    this.request();
  }

  draw(): void {
    const ctx = this.canvas.getContext("2d", { alpha: false });
    if (!ctx) return;
    const { scale, cx, cy } = this.view;
    const k = scale * this.dpr; // device px per mm
    ctx.setTransform(1, 0, 0, 1, 0, 0);
    ctx.fillStyle = "#fbfcfd";
    ctx.fillRect(0, 0, this.canvas.width, this.canvas.height);
    this.drawGrid(ctx, k);

    // mm -> device px: x' = (x - cx) k + W/2, y' = -(y - cy) k + H/2
    const W = this.canvas.width;
    const H = this.canvas.height;
    ctx.setTransform(k, 0, 0, -k, W / 2 - cx * k, H / 2 + cy * k);
    const half = this.dropletWidth / 2;
    const vis = {
      minX: cx - W / 2 / k - half,
      maxX: cx + W / 2 / k + half,
      minY: cy - H / 2 / k - half,
      maxY: cy + H / 2 / k + half,
    };
    const many = (this.current?.roles.length ?? 0) + (this.below?.roles.length ?? 0) > PIXEL_MODE_MIN_DROPLETS;
    const disc = this.dropletWidth * k;
    if (many && disc <= PIXEL_MODE_MAX) {
      this.drawPixels(ctx, k);
    } else if (disc <= STAMP_MAX) {
      this.drawStamped(ctx, k);
    } else {
      if (this.showBelow && this.below) this.drawDroplets(ctx, this.below, k, vis, true);
      if (this.current) this.drawDroplets(ctx, this.current, k, vis, false);
      const marks = this.marks();
      if (this.current && marks) this.drawOverhangs(ctx, this.current, marks, vis);
    }
    if (this.current && this.showTravel) this.drawTravel(ctx, this.current, k);
    if (this.current?.mask && this.showVoids) this.drawVoids(ctx, this.current.mask);
    ctx.setTransform(1, 0, 0, 1, 0, 0);
    if (this.current?.analysis && this.showVoids) this.drawLargestVoid(ctx, this.current, k);
    this.drawScaleBar(ctx);
    this.onDraw?.();
  }

  private image: ImageData | null = null;
  private scratch: OffscreenCanvas | null = null;
  private discs: DiscBuffer | null = null;
  private stamps: DiscStamps[] = [];
  /** The picture being painted into the pixel buffer (discs or, zoomed far out, squares): what
   *  it draws (compared item by item, the kind of painting first), its steps, and where it
   *  stands. */
  private painting: { key: unknown[]; steps: Step[]; step: number; next: number } | null = null;
  /** When the current draw stops painting (a `performance.now()`): a frame's draw
   *  FRAME_BUDGET_MS after it began, a direct `draw()` (the tests, a PNG export) never. */
  private deadline = Infinity;

  protected frameDraw(): void {
    // from the draw's start: a new picture's set-up (its buffer cleared, its disc stamps, the
    // droplets placed) counts against the frame's budget too
    this.deadline = performance.now() + FRAME_BUDGET_MS;
    try {
      this.draw();
    } finally {
      this.deadline = Infinity;
    }
  }

  /** The overhang marks of the current layer, when they belong to it. */
  private marks(): Uint8Array | null {
    const m = this.overhangs;
    return this.current && m && m.length === this.current.roles.length ? m : null;
  }

  /** The canvas-sized pixel buffer, cleared. */
  private pixelBuffer(): ImageData {
    const W = this.canvas.width;
    const H = this.canvas.height;
    if (!this.image || this.image.width !== W || this.image.height !== H) {
      this.image = new ImageData(W, H);
      this.scratch = new OffscreenCanvas(W, H);
      this.discs = new DiscBuffer(this.image);
    }
    this.discs!.clear();
    return this.image;
  }

  /** The pixel buffer over what is drawn. */
  private blit(ctx: CanvasRenderingContext2D): void {
    // only the box painted: a whole-canvas copy costs the page's thread 10–20 ms a frame
    const { x0, y0, x1, y1 } = this.discs!.dirty;
    if (!(x1 > x0 && y1 > y0)) return;
    this.scratch!.getContext("2d")!.putImageData(this.image!, 0, 0, x0, y0, x1 - x0, y1 - y0);
    ctx.save();
    ctx.setTransform(1, 0, 0, 1, 0, 0);
    ctx.drawImage(this.scratch!, x0, y0, x1 - x0, y1 - y0, x0, y0, x1 - x0, y1 - y0);
    ctx.restore();
  }

  /** Coverage stamps of a disc `diameter` device px wide (the last two sizes are kept). */
  private stampsFor(diameter: number): DiscStamps {
    const r = diameter / 2;
    let s = this.stamps.find((x) => x.radius === r);
    if (!s) {
      s = new DiscStamps(r);
      this.stamps = [s, ...this.stamps.slice(0, 1)];
    }
    return s;
  }

  /** Droplets as anti-aliased discs stamped into the pixel buffer: the layer below, the
   *  current layer's colour classes in CLASS_ORDER, the overhang marks over them. Within a
   *  frame's budget: what is left is stamped in the next frames (the picture so far shown),
   *  started again when anything it draws changes. */
  private drawStamped(ctx: CanvasRenderingContext2D, k: number): void {
    const { cx, cy } = this.view;
    const W = this.canvas.width;
    const H = this.canvas.height;
    const ox = W / 2 - cx * k;
    const oy = H / 2 + cy * k;
    const marks = this.marks();
    const below = this.showBelow ? this.below : null;
    const key = ["discs", this.current, below, marks, k, ox, oy, W, H, this.dropletWidth];
    this.paint(ctx, key, () => this.stampPasses(k, ox, oy, below, marks));
  }

  /** Paints the picture `key` within the draw's budget: its steps (`steps()`, made when the
   *  picture changes, in a fresh buffer) go on from where the last frame left them; what is
   *  painted so far is shown, and the next frame is asked for while steps are left. */
  private paint(ctx: CanvasRenderingContext2D, key: unknown[], steps: () => Step[]): void {
    let job = this.painting;
    if (!job || job.key.length !== key.length || job.key.some((v, i) => v !== key[i])) {
      this.pixelBuffer();
      job = this.painting = { key, steps: steps(), step: 0, next: 0 };
    }
    const deadline = this.deadline;
    while (job.step < job.steps.length) {
      const st = job.steps[job.step];
      job.next = st.run(job.next, deadline);
      if (job.next < st.count) break;
      job.step++;
      job.next = 0;
    }
    this.blit(ctx);
    if (job.step < job.steps.length) this.request();
  }

  /** The stamping's passes: the layer below, the colour classes, the overhang marks. */
  private stampPasses(k: number, ox: number, oy: number, below: LayerData | null, marks: Uint8Array | null): Step[] {
    const drop = this.stampsFor(this.dropletWidth * k);
    /** The layer's droplets in device px (x, y pairs). */
    const place = (layer: LayerData): Float64Array => {
      const d = layer.droplets;
      const n = layer.roles.length;
      const at = new Float64Array(2 * n);
      for (let i = 0; i < n; i++) {
        at[2 * i] = d[2 * i] * k + ox;
        at[2 * i + 1] = oy - d[2 * i + 1] * k;
      }
      return at;
    };
    const passes: StampPass[] = [];
    if (below) passes.push({ stamps: drop, color: rgb(BELOW_COLOR), at: place(below), count: below.roles.length, pick: null, want: 0 });
    const cur = this.current;
    if (cur) {
      const n = cur.roles.length;
      const at = place(cur);
      const cls = new Uint8Array(n);
      const has = new Uint8Array(CLASS_COLORS.length);
      for (let i = 0; i < n; i++) has[(cls[i] = dropletClass(cur.roles[i], cur.units?.[i] ?? 0))] = 1;
      // a pass walks every droplet: classes the layer has not (another unit's parts) are skipped
      for (const c of CLASS_ORDER) if (has[c] || c < 5) passes.push({ stamps: drop, color: rgb(CLASS_COLORS[c]), at, count: n, pick: cls, want: c });
      if (marks) passes.push({ stamps: this.stampsFor(this.dropletWidth * k * OVERHANG_DIAMETER), color: rgb(OVERHANG_COLOR), at, count: n, pick: marks, want: 1 });
    }
    const buf = this.discs!;
    return passes.map((p) => ({ count: p.count, run: (from, deadline) => buf.paint(p.stamps, p.color, p.at, p.count, p.pick, p.want, from, deadline) }));
  }

  /** Zoomed far out: droplets as squares of ceil(B) device pixels, written into the pixel
   *  buffer: the layer below, the current layer's colour classes in CLASS_ORDER, the overhang
   *  marks (squares 2 px wider) over them. Within a frame's budget, as the stamping: the 1M
   *  torus' layers (about 140,000 droplets each, with the layer below) took 40–60 ms in one
   *  frame. */
  private drawPixels(ctx: CanvasRenderingContext2D, k: number): void {
    const W = this.canvas.width;
    const H = this.canvas.height;
    const marks = this.marks();
    const below = this.showBelow ? this.below : null;
    const { cx, cy } = this.view;
    const key = ["squares", this.current, below, marks, k, cx, cy, W, H, this.dropletWidth];
    this.paint(ctx, key, () => {
      this.discs!.touchAll();
      return this.pixelSteps(k, below, marks);
    });
  }

  /** The square painting's steps: the layer below; the current layer's colour classes
   *  (computed once, in a step of their own), one step per class; the overhang marks. */
  private pixelSteps(k: number, below: LayerData | null, marks: Uint8Array | null): Step[] {
    const W = this.canvas.width;
    const H = this.canvas.height;
    const buf = this.discs!.pixels;
    const size = Math.max(1, Math.ceil(this.dropletWidth * k));
    const { cx, cy } = this.view;
    const ox = W / 2 - cx * k - size / 2;
    const oy = H / 2 + cy * k - size / 2;
    /** Squares of `n` px (centred as the droplets' `size`), in `color`, of the droplets of
     *  `layer` whose `pick` is `want` (every one without `pick`). */
    const paint = (layer: LayerData, n: number, color: number, pick: Uint8Array | null, want: number): Step => ({
      count: layer.roles.length,
      run: (from, deadline) => {
        const d = layer.droplets;
        const count = layer.roles.length;
        const shift = (n - size) / 2;
        for (let i = from; i < count; i++) {
          if (late(i, from, deadline)) return i;
          if (pick && pick[i] !== want) continue;
          const ix = Math.round(d[2 * i] * k + ox - shift);
          const iy = Math.round(-d[2 * i + 1] * k + oy - shift);
          if (ix < 0 || iy < 0 || ix + n > W || iy + n > H) continue;
          for (let r = 0; r < n; r++) {
            const row = (iy + r) * W + ix;
            for (let c = 0; c < n; c++) buf[row + c] = color;
          }
        }
        return count;
      },
    });
    const steps: Step[] = [];
    if (below) steps.push(paint(below, size, pixel(BELOW_COLOR), null, 0));
    const cur = this.current;
    if (cur) {
      const n = cur.roles.length;
      const cls = new Uint8Array(n);
      steps.push({
        count: n,
        run: (from, deadline) => {
          for (let i = from; i < n; i++) {
            if (late(i, from, deadline)) return i;
            cls[i] = dropletClass(cur.roles[i], cur.units?.[i] ?? 0);
          }
          return n;
        },
      });
      // the classes of units 2 and 3 only when the layer's units name them (a step walks every droplet)
      const has = new Uint8Array(CLASS_COLORS.length);
      const units = cur.units;
      if (units) for (let i = 0; i < units.length; i++) if (units[i] > 1) has[dropletClass(0, units[i])] = 1;
      for (const c of CLASS_ORDER) if (c < 5 || has[c]) steps.push(paint(cur, size, pixel(CLASS_COLORS[c]), cls, c));
      if (marks) steps.push(paint(cur, size + 2, pixel(OVERHANG_COLOR), marks, 1));
    }
    return steps;
  }

  private drawDroplets(ctx: CanvasRenderingContext2D, layer: LayerData, _k: number, vis: Bounds, faint: boolean): void {
    const d = layer.droplets;
    const roles = layer.roles;
    const units = layer.units;
    const r = this.dropletWidth / 2;
    const paths = faint ? [new Path2D()] : CLASS_COLORS.map(() => new Path2D());
    const n = roles.length;
    for (let i = 0; i < n; i++) {
      const x = d[2 * i];
      const y = d[2 * i + 1];
      if (x < vis.minX || x > vis.maxX || y < vis.minY || y > vis.maxY) continue;
      const p = faint ? paths[0] : paths[dropletClass(roles[i], units?.[i] ?? 0)];
      p.moveTo(x + r, y);
      p.arc(x, y, r, 0, 2 * Math.PI);
    }
    if (faint) {
      ctx.fillStyle = BELOW_COLOR;
      ctx.fill(paths[0]);
      return;
    }
    // support first, then fill, inner loops, the outer loop on top
    for (const cls of CLASS_ORDER) {
      ctx.fillStyle = CLASS_COLORS[cls];
      ctx.fill(paths[cls]);
    }
  }

  /** The unsupported droplets of the layer, as larger discs over the droplets. */
  private drawOverhangs(ctx: CanvasRenderingContext2D, layer: LayerData, marks: Uint8Array, vis: Bounds): void {
    const d = layer.droplets;
    const r = (this.dropletWidth * OVERHANG_DIAMETER) / 2;
    const p = new Path2D();
    for (let i = 0; i < marks.length; i++) {
      if (!marks[i]) continue;
      const x = d[2 * i];
      const y = d[2 * i + 1];
      if (x < vis.minX || x > vis.maxX || y < vis.minY || y > vis.maxY) continue;
      p.moveTo(x + r, y);
      p.arc(x, y, r, 0, 2 * Math.PI);
    }
    ctx.fillStyle = OVERHANG_COLOR;
    ctx.fill(p);
  }

  private maskImage: { mask: CoverageMask; canvases: (OffscreenCanvas | null)[] } | null = null;

  /** The mask's tiles as bitmaps, one pixel per cell, null for a tile with nothing to draw
   *  (made once per layer). */
  private maskBitmaps(m: CoverageMask): (OffscreenCanvas | null)[] {
    if (this.maskImage?.mask === m) return this.maskImage.canvases;
    const canvases = m.tiles.map((t) => {
      if (t.width === 0 || t.height === 0) return null;
      if (t.overfill.length === 0 && !t.void.some((v) => v !== 0)) return null;
      const img = new ImageData(t.width, t.height);
      const px = img.data;
      for (let row = 0; row < t.height; row++) {
        // bitmap row 0 is drawn at the origin's y: the flipped transform puts it at the bottom
        for (let col = 0; col < t.width; col++) {
          const i = row * t.width + col;
          const v = t.void[i];
          const o = t.overfill.length ? t.overfill[i] : 0;
          const [rgb, share] = o > v ? [OVERFILL_RGB, o] : [VOID_RGB, v];
          if (share === 0) continue;
          px[4 * i] = rgb[0];
          px[4 * i + 1] = rgb[1];
          px[4 * i + 2] = rgb[2];
          px[4 * i + 3] = Math.round(share * VOID_ALPHA);
        }
      }
      const canvas = new OffscreenCanvas(t.width, t.height);
      canvas.getContext("2d")!.putImageData(img, 0, 0);
      return canvas;
    });
    this.maskImage = { mask: m, canvases };
    return canvases;
  }

  /** Uncovered part area (and overfill) over the droplets, in the mm transform. */
  private drawVoids(ctx: CanvasRenderingContext2D, m: CoverageMask): void {
    const canvases = this.maskBitmaps(m);
    ctx.save();
    ctx.imageSmoothingEnabled = true;
    m.tiles.forEach((t, i) => {
      const c = canvases[i];
      if (c) ctx.drawImage(c, t.origin[0], t.origin[1], t.width * m.cell, t.height * m.cell);
    });
    ctx.restore();
  }

  /** A box around the layer's largest void and its area, in device pixels. */
  private drawLargestVoid(ctx: CanvasRenderingContext2D, layer: LayerData, k: number): void {
    const v = layer.analysis?.largest_void;
    if (!v) return;
    const { cx, cy } = this.view;
    const W = this.canvas.width;
    const H = this.canvas.height;
    const X = (x: number) => (x - cx) * k + W / 2;
    const Y = (y: number) => -(y - cy) * k + H / 2;
    const dpr = this.dpr;
    const pad = this.dropletWidth * k * 0.5 + 4 * dpr;
    const min = 14 * dpr;
    let x0 = X(v.min[0]) - pad;
    let x1 = X(v.max[0]) + pad;
    let y0 = Y(v.max[1]) - pad;
    let y1 = Y(v.min[1]) + pad;
    if (x1 - x0 < 2 * min) [x0, x1] = [X(v.centroid[0]) - min, X(v.centroid[0]) + min];
    if (y1 - y0 < 2 * min) [y0, y1] = [Y(v.centroid[1]) - min, Y(v.centroid[1]) + min];
    ctx.strokeStyle = "rgba(255, 255, 255, 0.9)";
    ctx.lineWidth = 4 * dpr;
    ctx.strokeRect(x0, y0, x1 - x0, y1 - y0);
    ctx.strokeStyle = VOID_MARK;
    ctx.lineWidth = 1.5 * dpr;
    ctx.setLineDash([5 * dpr, 3 * dpr]);
    ctx.strokeRect(x0, y0, x1 - x0, y1 - y0);
    ctx.setLineDash([]);
    const label = `Largest void ${v.area < 0.1 ? v.area.toFixed(3) : v.area.toFixed(2)} mm²`;
    drawTag(ctx, label, { size: 12 * dpr, pad: 6 * dpr, height: 20 * dpr, radius: 4 * dpr, color: VOID_MARK }, (tw, th) => [
      Math.min(Math.max(x0, 4 * dpr), W - tw - 4 * dpr),
      y0 - th - 4 * dpr >= 4 * dpr ? y0 - th - 4 * dpr : y1 + 4 * dpr,
    ]);
  }

  private drawTravel(ctx: CanvasRenderingContext2D, layer: LayerData, k: number): void {
    const t = layer.travel;
    const p = new Path2D();
    for (let i = 0; i + 3 < t.length; i += 4) {
      p.moveTo(t[i], t[i + 1]);
      p.lineTo(t[i + 2], t[i + 3]);
    }
    ctx.strokeStyle = TRAVEL_COLOR;
    ctx.lineWidth = 1 / k;
    ctx.setLineDash([4 / k, 3 / k]);
    ctx.stroke(p);
    ctx.setLineDash([]);
  }

  private gridStep(): number {
    // about 60 CSS px between grid lines, 1-2-5 steps
    const target = 60 / this.view.scale;
    const p = Math.pow(10, Math.floor(Math.log10(target)));
    for (const m of [1, 2, 5, 10]) if (m * p >= target) return m * p;
    return 10 * p;
  }

  /**
   * The grid, computed in canvas space: the lines on screen are counted first (an integer,
   * at most [[MAX_GRID_LINES]]) and placed at `first + i * spacing` device pixels, so no loop
   * depends on a step in mm that might not advance a far-away coordinate.
   */
  private drawGrid(ctx: CanvasRenderingContext2D, k: number): void {
    const W = this.canvas.width;
    const H = this.canvas.height;
    const { cx, cy } = this.view;
    const step = this.gridStep();
    const spacing = step * k; // device px between lines
    if (!Number.isFinite(spacing) || spacing < 2) return;
    const minor = new Path2D();
    const axes = new Path2D();
    // x: line i (an integer) is at x = i * step; on screen at (i * step - cx) * k + W / 2
    const lines = (size: number, centre: number, flip: boolean, add: (path: Path2D, at: number) => void) => {
      // the canvas edge in mm and the first line's offset from it, in device px
      const edge = flip ? centre + size / 2 / k : centre - size / 2 / k;
      const first = flip ? Math.floor(edge / step) : Math.ceil(edge / step);
      let offset = Math.abs(first * step - edge) * k;
      if (!(offset >= 0 && offset < spacing)) offset = 0; // far from the origin, precision is gone
      const count = Math.min(MAX_GRID_LINES, Math.floor((size - offset) / spacing) + 1);
      const axis = flip ? (centre * k + size / 2) : (-centre * k + size / 2); // where 0 mm falls
      for (let i = 0; i < count; i++) {
        const at = offset + i * spacing;
        const px = Math.round(at) + 0.5;
        add(Math.abs(at - axis) < spacing / 2 ? axes : minor, px);
      }
    };
    lines(W, cx, false, (path, px) => {
      path.moveTo(px, 0);
      path.lineTo(px, H);
    });
    lines(H, cy, true, (path, py) => {
      path.moveTo(0, py);
      path.lineTo(W, py);
    });
    ctx.lineWidth = 1;
    ctx.strokeStyle = "#e9ecf1";
    ctx.stroke(minor);
    ctx.strokeStyle = "#c9ced8";
    ctx.stroke(axes);
  }

  private drawScaleBar(ctx: CanvasRenderingContext2D): void {
    const step = this.gridStep();
    const dpr = this.dpr;
    const len = step * this.view.scale * dpr;
    const x = 16 * dpr;
    const y = this.canvas.height - 18 * dpr;
    const label = `${+step.toPrecision(3)} mm`;
    ctx.font = `${12 * dpr}px system-ui, sans-serif`;
    const w = len + ctx.measureText(label).width + 20 * dpr;
    ctx.fillStyle = "rgba(255, 255, 255, 0.85)";
    ctx.beginPath();
    ctx.roundRect(x - 8 * dpr, y - 16 * dpr, w, 26 * dpr, 5 * dpr);
    ctx.fill();
    ctx.strokeStyle = "#495057";
    ctx.lineWidth = 2 * dpr;
    ctx.beginPath();
    ctx.moveTo(x, y - 5 * dpr);
    ctx.lineTo(x, y);
    ctx.lineTo(x + len, y);
    ctx.lineTo(x + len, y - 5 * dpr);
    ctx.stroke();
    ctx.fillStyle = "#495057";
    ctx.textBaseline = "bottom";
    ctx.fillText(label, x + len + 6 * dpr, y + 5 * dpr);
  }
}

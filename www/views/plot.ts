// The per-layer plot under the layer slider: droplets per layer (bars stacked by what prints
// them: each unit's parts, unit 0 first, then the support; their sum is the statistics' *This layer*)
// and the running print time (a line, the right axis) along the layers, the current layer
// marked. A click or a drag goes to the layer under the pointer (as the slider does); hovering
// shows that layer's figures. The canvas is a slider for the keyboard (focusable; the page's
// arrow keys move the layer, views/layer.ts) with the readout as its value text. Every figure is the core's: droplets per layer, and the time of each layer
// (src/output/summary.rs `layer_seconds`, which add up to the job's print time); the running time is
// their prefix sum. Layers are binned to device pixels (a column shows its tallest layer), so a
// draw costs O(layers + width) whatever the count; while the workers run it is redrawn at most
// every [[BUSY_REDRAW_MS]].

import { sizeCanvas, watchCanvas } from "./canvas/hidpi";
import type { Page } from "./page";
import type { LayerCounts } from "../core/protocol";
import type { Slice } from "../core/store";
import { UNIT_BARS, unitColor, unitsOf } from "../core/units";
import { $, duration, el, nf, unitRows } from "./dom";

const BUSY_REDRAW_MS = 150;
/** The plot area inside the canvas, CSS pixels: room for the axes' labels. */
const PAD = { left: 58, right: 62, top: 16, bottom: 28 };
/** The stack's colours, bottom up: each unit's parts (core/units.ts `UNIT_BARS`), the support
 *  (the legend's swatches in style.css `.plot-key i.*` match). */
const SUPPORT_BAR = "#86d0dc";
const barColor = (j: number, n: number) => (j < n ? unitColor(UNIT_BARS, j) : SUPPORT_BAR);
const BAR_EMPTY = "#eef1f5";
const LINE = "#d9480f";
/** The time axis' labels: darker than the line, for text contrast ≥ 4.5:1 on white. */
const LINE_TEXT = "#c2410c";
const AXIS = "#5c6773";
const GRID = "#e3e7ee";
const MARK = "#1f2933";
const FONT = '11px system-ui, -apple-system, "Segoe UI", Roboto, sans-serif';

interface Sums {
  slice: Slice;
  done: number;
  /** start[i]: seconds before layer i starts (start[layers] = the whole time). */
  start: Float64Array;
  /** Every layer has its time (a slice; not a .gco file, not a slice half done). */
  timed: boolean;
}

let page: Page | null = null;
let canvas: HTMLCanvasElement | null = null;
let frame = 0;
let timer = 0;
let lastDraw = -Infinity;
let hover: number | null = null;
let sums: Sums | null = null;

/** The prefix sums of the layers' times (recomputed when layers arrived). */
function sumsOf(s: Slice): Sums {
  if (sums && sums.slice === s && sums.done === s.done) return sums;
  const n = s.layers;
  const start = new Float64Array(n + 1);
  let timed = n > 0;
  for (let i = 0; i < n; i++) {
    const t = s.layerSeconds[i];
    if (t === undefined) timed = false;
    start[i + 1] = start[i] + (t ?? 0);
  }
  sums = { slice: s, done: s.done, start, timed: timed && s.source === "stl" };
  return sums;
}

/** A layer's droplets by what prints them: each of `n` units' parts (unit 0 first), then the
 *  support (n + 1 numbers; the roles partition the droplets). */
export function stackOf(c: LayerCounts, n: number): number[] {
  const out = new Array<number>(n + 1).fill(0);
  c.parts.forEach((d, u) => (out[Math.min(u, n - 1)] += d));
  out[n] = c.support ?? 0;
  return out;
}

/** A layer's droplets, all of them: the statistics' *This layer*. */
export function layerTotal(c: LayerCounts): number {
  return c.outer + c.inner + c.fill + (c.support ?? 0);
}

/** The layer under CSS x (clamped), for `layers` layers in a canvas `width` CSS pixels wide. */
function layerAt(x: number, width: number, layers: number): number {
  const w = Math.max(1, width - PAD.left - PAD.right);
  return Math.max(0, Math.min(layers - 1, Math.floor(((x - PAD.left) / w) * layers)));
}

/** Ticks 1-2-5 × 10^k: at most `most` of them over [0, max]. */
function step(max: number, most: number): number {
  const raw = max / Math.max(1, most);
  const p = 10 ** Math.floor(Math.log10(Math.max(raw, 1e-12)));
  for (const m of [1, 2, 5, 10]) if (m * p >= raw) return m * p;
  return 10 * p;
}

/** Short time for the axis: "2 h", "35 min", "40 s". */
function shortTime(seconds: number): string {
  if (seconds >= 3600) return `${+(seconds / 3600).toFixed(seconds >= 36000 ? 0 : 1)} h`;
  if (seconds >= 60) return `${Math.round(seconds / 60)} min`;
  return `${Math.round(seconds)} s`;
}

/** The label: the hovered layer's figures, or the current layer's. */
function writeLabel(): void {
  if (!page) return;
  const out = $("plot-label");
  const s = page.store.slice;
  if (!s || s.layers === 0) {
    out.textContent = "";
    return;
  }
  const i = hover ?? page.store.current;
  const text = readout(s, i);
  out.textContent = text;
  out.title = text; // the whole readout where one line cuts it short
  if (canvas) {
    canvas.setAttribute("aria-valuemax", String(s.layers));
    canvas.setAttribute("aria-valuenow", String(page.store.current + 1));
    canvas.setAttribute("aria-valuetext", hover === null ? text : readout(s, page.store.current));
  }
}

/** Layer i's figures in words: its droplets (the total, then by what prints them when a unit
 *  but unit 0 prints any), its time and when it starts. */
function readout(s: Slice, i: number): string {
  const c = s.counts[i];
  const z = s.z[i];
  const parts = [`Layer ${i + 1}`];
  if (z !== undefined) parts.push(`z ${z.toFixed(2)} mm`);
  if (c) {
    const n = s.unitCount;
    const stack = stackOf(c, n);
    const split = stack.flatMap((d, j) => (j === 0 || d === 0 ? [] : [`${nf.format(d)} ${j < n ? `unit ${j}` : "support"}`]));
    parts.push(`${nf.format(layerTotal(c))} droplets` + (split.length ? ` (${nf.format(stack[0])} unit 0, ${split.join(", ")})` : ""));
  } else parts.push("not sliced yet");
  const t = s.layerSeconds[i];
  if (t !== undefined) parts.push(`${duration(t)} to print`);
  let text = parts.join(" · ");
  const sum = sumsOf(s);
  if (sum.timed) text += ` — layer ${i + 1} starts after ${duration(sum.start[i])}`;
  return text;
}

/** The legend's entries for what the slice has (`kinds`: each of n units' parts, then the
 *  support): unit 0 always, another unit's parts and the support when some layer has them. */
function writeKey(kinds: boolean[]): void {
  const n = kinds.length - 1;
  const support = $("plot-key-support");
  unitRows("key", support, n, (u) => [el("span", { id: `plot-key-unit${u}`, hidden: "" }, el("i", { class: `bar${u}` }), `unit ${u}`)], true);
  for (let u = 1; u < n; u++) $(`plot-key-unit${u}`).hidden = !kinds[u];
  support.hidden = !kinds[n];
}

/** Draws the plot now. */
export function drawPlot(): void {
  if (!page || !canvas) return;
  lastDraw = performance.now();
  // sized before the label changes: reading the box then forces no layout of the page
  const { cssW, cssH, dpr } = sizeCanvas(canvas);
  writeLabel();
  const W = canvas.width;
  const H = canvas.height;
  const g = canvas.getContext("2d");
  if (!g) return;
  g.setTransform(1, 0, 0, 1, 0, 0);
  g.clearRect(0, 0, W, H);
  const s = page.store.slice;
  const n = s?.layers ?? 0;
  canvas.dataset.layers = String(n);
  canvas.setAttribute("aria-valuemin", "1");
  canvas.dataset.left = String(PAD.left);
  canvas.dataset.right = String(cssW - PAD.right);
  const units = s ? s.unitCount : unitsOf(page.form?.values());
  if (!s || n === 0) {
    writeKey([true, ...new Array<boolean>(units).fill(false)]);
    return;
  }

  // the plot area in device pixels
  const x0 = Math.round(PAD.left * dpr);
  const x1 = Math.round((cssW - PAD.right) * dpr);
  const y0 = Math.round(PAD.top * dpr);
  const y1 = Math.round((cssH - PAD.bottom) * dpr);
  const cols = Math.max(1, x1 - x0);
  const h = Math.max(1, y1 - y0);

  // bin the layers to columns: each column shows its tallest layer (its index, -1: none in
  // yet) and whether any is missing
  const tallest = new Float64Array(cols);
  const which = new Int32Array(cols).fill(-1);
  const missing = new Uint8Array(cols);
  let maxDroplets = 0;
  const kinds = new Array<boolean>(units + 1).fill(false);
  for (let c = 0; c < cols; c++) {
    const a = Math.floor((c * n) / cols);
    const b = Math.max(a + 1, Math.floor(((c + 1) * n) / cols));
    let m = -1;
    for (let i = a; i < b; i++) {
      const k = s.counts[i];
      if (!k) {
        missing[c] = 1;
        continue;
      }
      const d = layerTotal(k);
      if (d > m) {
        m = d;
        which[c] = i;
      }
    }
    tallest[c] = Math.max(0, m);
    if (m > maxDroplets) maxDroplets = m;
  }
  for (const k of s.counts) if (k) stackOf(k, units).forEach((v, j) => (kinds[j] ||= v > 0));
  writeKey(kinds);
  // whole droplets and whole layers per tick
  const dStep = Math.max(1, step(maxDroplets, Math.max(1, Math.floor(h / (22 * dpr)))));
  const dTop = Math.max(dStep, Math.ceil(maxDroplets / dStep) * dStep);
  const sum = sumsOf(s);
  const total = sum.start[n];

  g.font = FONT.replace("11px", `${11 * dpr}px`);
  g.textBaseline = "middle";
  // horizontal grid and the droplets' axis (left), in thousands when they reach 10,000
  const thousands = dTop >= 10000;
  g.fillStyle = AXIS;
  g.textAlign = "right";
  for (let v = 0; v <= dTop + 1e-9; v += dStep) {
    const y = Math.round(y1 - (v / dTop) * h) + 0.5;
    g.fillStyle = GRID;
    g.fillRect(x0, y - 0.5, cols, Math.max(1, Math.round(dpr / 2)));
    g.fillStyle = AXIS;
    g.fillText(thousands && v > 0 ? `${+(v / 1000).toFixed(1)}k` : nf.format(v), x0 - 5 * dpr, y);
  }
  g.save();
  g.translate(11 * dpr, (y0 + y1) / 2);
  g.rotate(-Math.PI / 2);
  g.textAlign = "center";
  g.fillText("droplets", 0, 0);
  g.restore();

  // the bars
  for (let c = 0; c < cols; c++) {
    if (missing[c] && tallest[c] === 0) {
      g.fillStyle = BAR_EMPTY;
      g.fillRect(x0 + c, y1 - 2 * dpr, 1, 2 * dpr);
      continue;
    }
    if (which[c] < 0) continue;
    let y = y1;
    stackOf(s.counts[which[c]]!, units).forEach((v, j) => {
      const bh = (v / dTop) * h;
      g.fillStyle = barColor(j, units);
      g.fillRect(x0 + c, y - bh, 1, bh);
      y -= bh;
    });
  }

  // the running time (right axis), interpolated within a layer
  if (total > 0) {
    g.strokeStyle = LINE;
    g.lineWidth = 1.5 * dpr;
    g.lineJoin = "round";
    g.beginPath();
    for (let c = 0; c <= cols; c++) {
      const t = (c / cols) * n;
      const i = Math.min(n - 1, Math.floor(t));
      const v = sum.start[i] + (sum.start[i + 1] - sum.start[i]) * (t - i);
      const y = y1 - (v / total) * h;
      if (c === 0) g.moveTo(x0 + c, y);
      else g.lineTo(x0 + c, y);
    }
    g.stroke();
    g.fillStyle = LINE_TEXT;
    g.textAlign = "left";
    for (const f of [0, 0.5, 1]) g.fillText(shortTime(total * f), x1 + 5 * dpr, y1 - f * h);
    g.save();
    g.translate(W - 9 * dpr, (y0 + y1) / 2);
    g.rotate(Math.PI / 2);
    g.textAlign = "center";
    g.fillText(sum.timed ? "time so far" : "time (partial)", 0, 0);
    g.restore();
  }

  // the layer axis (bottom): layer numbers, the z of each tick beneath
  g.fillStyle = AXIS;
  g.fillRect(x0, y1, cols, Math.max(1, Math.round(dpr)));
  const lStep = Math.max(1, step(n, Math.max(1, Math.floor(cols / (64 * dpr)))));
  g.textAlign = "center";
  const xOf = (i: number) => x0 + ((i + 0.5) / n) * cols;
  for (let l = lStep; l <= n; l += lStep) {
    const x = xOf(l - 1);
    g.fillRect(Math.round(x), y1, Math.max(1, Math.round(dpr)), 3 * dpr);
    const z = s.z[l - 1];
    g.fillText(z !== undefined ? `${l} · ${z.toFixed(1)}` : String(l), x, y1 + 12 * dpr);
  }
  g.textAlign = "left";
  g.fillText("layer · z mm", 4 * dpr, y1 + 12 * dpr);

  // the hovered layer and the current one
  const mark = (i: number, color: string, width: number) => {
    const x = Math.round(xOf(i));
    g.fillStyle = color;
    g.fillRect(x - Math.floor(width / 2), y0 - 4 * dpr, width, y1 - y0 + 4 * dpr);
  };
  if (hover !== null && hover !== page.store.current) mark(hover, "rgba(31,41,51,.35)", Math.max(1, Math.round(dpr)));
  mark(page.store.current, MARK, Math.max(2, Math.round(2 * dpr)));
  const cx = Math.round(xOf(page.store.current));
  g.beginPath();
  g.moveTo(cx - 5 * dpr, y0 - 9 * dpr);
  g.lineTo(cx + 5 * dpr, y0 - 9 * dpr);
  g.lineTo(cx, y0 - 3 * dpr);
  g.closePath();
  g.fillStyle = MARK;
  g.fill();
}

/** Asks for a redraw: on the next frame, or while the workers run at most every
 *  [[BUSY_REDRAW_MS]] (a draw costs time taken from slicing on few cores). A throttled draw
 *  runs in its timer's own task, not in the next frame's: there it added its 8–17 ms to the
 *  layer canvas' draw, the paint and the commit in one task of the page's thread. */
export function requestPlot(): void {
  if (!page || frame || timer) return;
  if (page.store.busy) {
    timer = window.setTimeout(
      () => {
        timer = 0;
        drawPlot();
      },
      Math.max(0, lastDraw + BUSY_REDRAW_MS - performance.now()),
    );
    return;
  }
  frame = requestAnimationFrame(() => {
    frame = 0;
    drawPlot();
  });
}

/** The plot's canvas: resize, click and drag to a layer, hover. */
export function wirePlot(p: Page, goTo: (layer: number) => void): void {
  page = p;
  const c = $<HTMLCanvasElement>("plot");
  canvas = c;
  watchCanvas(c, () => requestPlot());
  const at = (ev: PointerEvent) => {
    const s = p.store.slice;
    if (!s || s.layers === 0) return null;
    const r = c.getBoundingClientRect();
    return layerAt(ev.clientX - r.left, r.width, s.layers);
  };
  let drag: number | null = null;
  c.addEventListener("pointerdown", (ev) => {
    const i = at(ev);
    if (i === null) return;
    drag = ev.pointerId;
    c.setPointerCapture(ev.pointerId);
    hover = null;
    goTo(i);
  });
  c.addEventListener("pointermove", (ev) => {
    const i = at(ev);
    if (i === null) return;
    if (drag === ev.pointerId) {
      if (i !== p.store.current) goTo(i);
    } else if (hover !== i) {
      hover = i;
      requestPlot();
    }
  });
  const end = () => (drag = null);
  c.addEventListener("pointerup", end);
  c.addEventListener("pointercancel", end);
  c.addEventListener("pointerleave", () => {
    if (drag !== null) return;
    hover = null;
    requestPlot();
  });
}

// The vertical cut: a line on the layer view (the "Cut" tool: drag a line across the part,
// drag its ends or the line to move it; or "x =" / "y =" a position), drawn on the layer
// canvas, and the section through the stacked layers below it (cutrender.ts).
//
// Droplets near the line come from the page's cache at once (binned once per layer and line:
// t, d, role); the part's section along the line and the 3D estimate's voids come from the
// workers (src/wasm_cut.rs), in runs of layers from the one shown outwards, a few at a time.
// The page sends the droplets near the line of the layers it holds; a layer it does not hold
// (evicted) is planned by the worker, which returns its droplets near the line: the page never
// fetches layers' full previews for the cut. A new line drops the runs not yet sent.

import { Cancelled } from "../client";
import { CutRenderer, type CutLayer } from "../cutrender";
import { showError } from "../errors";
import type { Page } from "../page";
import { NOT_SENT, type CutReply, type LayerData } from "../protocol";
import { dropletClass } from "../render";
import type { Slice } from "../store";
import { $ } from "./dom";

type Pt = [number, number];
export interface Line {
  a: Pt;
  b: Pt;
}

/** Layers per request to a worker. */
const RUN = 24;
/** The longest line accepted (mm), as the core's `MAX_CUT_LENGTH`. */
const MAX_LENGTH = 10_000;
/** Pointer distance (CSS px) that grabs an end or the line. */
const GRAB_PX = 9;

interface State {
  line: Line | null;
  /** The "Cut" tool: a drag on the layer canvas draws a new line. */
  tool: boolean;
  slice: Slice | null;
  /** Bumped by every new line or slice: replies of an older one are dropped. */
  gen: number;
  /** Runs of layers still to ask the workers for, and how many are out. */
  queue: [number, number][];
  inFlight: number;
  /** Layers whose section and voids arrived (for the current line). */
  resolved: Set<number>;
  /** Layers the page has handed to the cut from its cache (for the current line). */
  binned: Set<number>;
  error: string | null;
}

const state: State = { line: null, tool: false, slice: null, gen: 0, queue: [], inFlight: 0, resolved: new Set(), binned: new Set(), error: null };
let cut: CutRenderer | null = null;
let timer = 0;

/** The footprint radius R of the analysis' footprint setting (disc: B/2; spread: B/√π). */
function radiusOf(s: Slice): number {
  return s.settings.footprint === "spread" ? s.dropletWidth / Math.sqrt(Math.PI) : s.dropletWidth / 2;
}

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

function length(l: Line): number {
  return Math.hypot(l.b[0] - l.a[0], l.b[1] - l.a[1]);
}

/** t, d, colour class (render.ts `dropletClass`) of a layer's droplets whose footprint (radius `radius`) the plane crosses, and
 *  x, y of those within `reach` of the line (sent to the core). */
function bin(layer: LayerData, l: Line, reach: number, radius: number): { near: Float64Array; xy: Float64Array } {
  const len = length(l);
  const ux = (l.b[0] - l.a[0]) / len;
  const uy = (l.b[1] - l.a[1]) / len;
  const d = layer.droplets;
  const near: number[] = [];
  const xy: number[] = [];
  for (let i = 0; i < layer.roles.length; i++) {
    const x = d[2 * i] - l.a[0];
    const y = d[2 * i + 1] - l.a[1];
    const dist = ux * y - uy * x;
    if (dist > reach || dist < -reach) continue;
    const t = ux * x + uy * y;
    if (t < -reach || t > len + reach) continue;
    xy.push(d[2 * i], d[2 * i + 1]);
    if (Math.abs(dist) < radius && t > -radius && t < len + radius) near.push(t, Math.abs(dist), dropletClass(layer.roles[i], layer.units?.[i] ?? 0));
  }
  return { near: Float64Array.from(near), xy: Float64Array.from(xy) };
}

/** Page-side copies of the droplets near the line (x, y) per layer, for the requests. */
const sentXY = new Map<number, Float64Array>();

/** Bins the cached layers not binned yet for this line; returns whether any was. */
function binCached(page: Page): boolean {
  const s = page.store.slice;
  if (!s || !state.line || !cut) return false;
  let added = false;
  for (const [i, layer] of s.cache) {
    if (state.binned.has(i)) continue;
    const { near, xy } = bin(layer, state.line, s.dropletWidth, radiusOf(s));
    const old = cut.layers.get(i);
    cut.layers.set(i, { near, spans: old?.spans ?? null, voids: old?.voids ?? null });
    sentXY.set(i, xy);
    state.binned.add(i);
    added = true;
  }
  return added;
}

/** Fills the request queue: runs of layers not resolved, from the layer shown outwards. */
function plan(page: Page): void {
  const s = page.store.slice;
  state.queue = [];
  if (!s || !state.line || !s.complete || s.source !== "stl") return;
  const runs: [number, number][] = [];
  for (let from = 0; from < s.layers; from += RUN) runs.push([from, Math.min(s.layers, from + RUN)]);
  const c = page.store.current;
  const far = (r: [number, number]) => (c < r[0] ? r[0] - c : c >= r[1] ? c - r[1] + 1 : 0);
  state.queue = runs.filter(([a, b]) => {
    for (let i = a; i < b; i++) if (!state.resolved.has(i)) return true;
    return false;
  }).sort((x, y) => far(x) - far(y));
  pump(page);
}

/** Sends queued runs while fewer than one per worker are out. */
function pump(page: Page): void {
  const s = page.store.slice;
  while (s && state.line && state.inFlight < page.pool.size && state.queue.length) {
    const [from, to] = state.queue.shift()!;
    const lo = Math.max(0, from - 1);
    const hi = Math.min(s.layers, to + 1);
    const sent = new Uint32Array(hi - lo);
    const parts: Float64Array[] = [];
    for (let i = lo; i < hi; i++) {
      const xy = state.binned.has(i) ? sentXY.get(i) : undefined;
      if (xy) {
        sent[i - lo] = xy.length / 2;
        parts.push(xy);
      } else sent[i - lo] = NOT_SENT;
    }
    const centres = new Float64Array(parts.reduce((n, p) => n + p.length, 0));
    let at = 0;
    for (const p of parts) {
      centres.set(p, at);
      at += p.length;
    }
    const l = state.line;
    const gen = state.gen;
    // `sent` is transferred to the worker: the reply is read with a copy
    const flags = sent.slice();
    state.inFlight++;
    page.pool
      .cut({ line: [l.a[0], l.a[1], l.b[0], l.b[1]], from, to, sent, centres })
      .then((r) => {
        if (gen === state.gen) take(r, from, to, flags, lo);
      })
      .catch((e) => {
        if (e instanceof Cancelled || gen !== state.gen) return;
        state.error = e instanceof Error ? e.message : String(e);
        showError(page, e);
      })
      .finally(() => {
        if (gen === state.gen) state.inFlight--;
        pump(page);
        update(page);
      });
  }
}

/** A worker's reply for layers [from, to). */
function take(r: CutReply, from: number, to: number, sent: Uint32Array, lo: number): void {
  if (!cut) return;
  const per = <T>(flat: Float64Array, stride: number, f: (i: number, at: number) => T) => {
    for (let j = 0; j + stride - 1 < flat.length; j += stride) f(flat[j], j);
  };
  const spans = new Map<number, number[]>();
  const voids = new Map<number, number[]>();
  const planned = new Map<number, number[]>();
  per(r.spans, 3, (i, j) => (spans.get(i) ?? spans.set(i, []).get(i)!).push(r.spans[j + 1], r.spans[j + 2]));
  per(r.voids, 4, (i, j) => (voids.get(i) ?? voids.set(i, []).get(i)!).push(r.voids[j + 1], r.voids[j + 2], r.voids[j + 3]));
  per(r.droplets, 5, (i, j) => (planned.get(i) ?? planned.set(i, []).get(i)!).push(r.droplets[j + 1], r.droplets[j + 2], dropletClass(r.droplets[j + 3], r.droplets[j + 4])));
  for (let i = from; i < to; i++) {
    const old = cut.layers.get(i);
    const near = sent[i - lo] === NOT_SENT ? Float64Array.from(planned.get(i) ?? []) : (old?.near ?? new Float64Array(0));
    const layer: CutLayer = { near, spans: Float64Array.from(spans.get(i) ?? []), voids: Float64Array.from(voids.get(i) ?? []) };
    cut.layers.set(i, layer);
    state.resolved.add(i);
  }
}

/** Starts over for a new line (or slice): everything of the old one is dropped. */
function reset(page: Page): void {
  state.gen++;
  state.queue = [];
  state.inFlight = 0;
  state.resolved = new Set();
  state.binned = new Set();
  state.error = null;
  sentXY.clear();
  state.slice = page.store.slice;
  if (cut) {
    cut.layers = new Map();
    cut.length = state.line ? length(state.line) : 0;
  }
}

/** Keeps the cut in step with the page: a new slice, layers that arrived, the layer shown. */
function update(page: Page): void {
  if (!cut || !state.line) return;
  const s = page.store.slice;
  if (s !== state.slice) {
    reset(page);
    if (s) plan(page);
  }
  if (!s) return;
  cut.z = s.z;
  cut.layerHeight = s.layerHeight;
  cut.radius = radiusOf(s);
  cut.current = page.store.current;
  binCached(page);
  if (s.complete && s.source === "stl" && state.queue.length === 0 && state.inFlight === 0 && state.resolved.size < s.layers) plan(page);
  cut.request();
  const status = $("cut-status");
  const pending = s.source === "stl" ? s.layers - state.resolved.size : 0;
  status.textContent =
    `${length(state.line).toFixed(1)} mm` +
    (s.source === "gco" ? " · voids need a model, not a .gco file" : pending > 0 ? ` · section of ${s.layers - pending} / ${s.layers} layers` : "");
}

/** Sets the cut line (null: no cut) and shows the cut view. */
export function setLine(page: Page, line: Line | null, refit = true): void {
  state.line = line;
  $("cut-panel").hidden = !line;
  page.renderer.request();
  if (!line || !cut) return;
  reset(page);
  update(page);
  if (refit) {
    cut.touched = false;
    cut.fit();
  }
}

/** The line a little longer than the part, through `v` on the other axis. */
function axisLine(page: Page, axis: "x" | "y", v: number): Line | null {
  const s = page.store.slice;
  if (!s || !Number.isFinite(v)) return null;
  const b = s.info.bounds ? { minX: s.info.bounds.min[0], maxX: s.info.bounds.max[0], minY: s.info.bounds.min[1], maxY: s.info.bounds.max[1] } : s.bbox;
  if (!(b.maxX >= b.minX)) return null;
  const m = 1;
  return checkLine(axis === "y" ? { a: [b.minX - m, v], b: [b.maxX + m, v] } : { a: [v, b.minY - m], b: [v, b.maxY + m] });
}

/** The line on the layer canvas (after every draw of it), with its ends as handles. */
function drawOnLayer(page: Page): void {
  const l = state.line;
  if (!l) return;
  const r = page.renderer;
  const ctx = r.canvas.getContext("2d");
  if (!ctx) return;
  const dpr = window.devicePixelRatio || 1;
  const [ax, ay] = r.toPx(l.a[0], l.a[1]).map((v) => v * dpr);
  const [bx, by] = r.toPx(l.b[0], l.b[1]).map((v) => v * dpr);
  ctx.save();
  ctx.setTransform(1, 0, 0, 1, 0, 0);
  ctx.lineCap = "round";
  ctx.strokeStyle = "rgba(255, 255, 255, 0.9)";
  ctx.lineWidth = 5 * dpr;
  ctx.beginPath();
  ctx.moveTo(ax, ay);
  ctx.lineTo(bx, by);
  ctx.stroke();
  ctx.strokeStyle = "#1c2430";
  ctx.lineWidth = 1.8 * dpr;
  ctx.setLineDash([8 * dpr, 5 * dpr]);
  ctx.stroke();
  ctx.setLineDash([]);
  for (const [x, y, name] of [[ax, ay, "A"], [bx, by, "B"]] as const) {
    ctx.fillStyle = "#fff";
    ctx.strokeStyle = "#1c2430";
    ctx.lineWidth = 1.8 * dpr;
    ctx.beginPath();
    ctx.arc(x, y, 6 * dpr, 0, 2 * Math.PI);
    ctx.fill();
    ctx.stroke();
    ctx.fillStyle = "#1c2430";
    ctx.font = `600 ${11 * dpr}px system-ui, sans-serif`;
    ctx.textBaseline = "bottom";
    ctx.fillText(name, x + 8 * dpr, y - 6 * dpr);
  }
  ctx.restore();
}

/** What a pointer at CSS px (x, y) grabs: an end, the line, or nothing. */
function grab(page: Page, x: number, y: number): "a" | "b" | "line" | null {
  const l = state.line;
  if (!l) return null;
  const r = page.renderer;
  const a = r.toPx(l.a[0], l.a[1]);
  const b = r.toPx(l.b[0], l.b[1]);
  if (Math.hypot(x - a[0], y - a[1]) <= GRAB_PX) return "a";
  if (Math.hypot(x - b[0], y - b[1]) <= GRAB_PX) return "b";
  const dx = b[0] - a[0];
  const dy = b[1] - a[1];
  const len2 = dx * dx + dy * dy;
  const u = len2 > 0 ? Math.max(0, Math.min(1, ((x - a[0]) * dx + (y - a[1]) * dy) / len2)) : 0;
  return Math.hypot(x - a[0] - u * dx, y - a[1] - u * dy) <= GRAB_PX / 1.5 ? "line" : null;
}

function setTool(page: Page, on: boolean): void {
  state.tool = on;
  const btn = $("btn-cut");
  btn.setAttribute("aria-pressed", String(on));
  btn.classList.toggle("active", on);
  page.renderer.canvas.classList.toggle("cutting", on);
}

/** The tool, the numeric position, the cut canvas' zoom and pan; returns the tests' hooks. */
export function wireCut(page: Page) {
  const { renderer } = page;
  cut = new CutRenderer($<HTMLCanvasElement>("cut-view"));
  const prevDraw = renderer.onDraw;
  renderer.onDraw = () => {
    prevDraw?.();
    drawOnLayer(page);
    if (state.line && cut) {
      cut.current = page.store.current;
      // a new slice, new layers or another layer shown: later, not inside the layer's draw
      clearTimeout(timer);
      timer = window.setTimeout(() => update(page), 30);
    }
  };

  // a slice that completed (or layers that arrived) while the layer canvas was not redrawn
  let seen = "";
  setInterval(() => {
    const s = page.store.slice;
    const now = s && state.line ? `${s.done}/${s.complete}/${page.store.current}/${s.cache.size}` : "";
    if (now !== seen) {
      seen = now;
      if (now) update(page);
    }
  }, 400);

  $("btn-cut").addEventListener("click", () => {
    setTool(page, !state.tool);
    const s = page.store.slice;
    if (state.tool && !state.line && s) {
      const b = s.info.bounds;
      const y = b ? (b.min[1] + b.max[1]) / 2 : (s.bbox.minY + s.bbox.maxY) / 2;
      setLine(page, axisLine(page, "y", y));
    }
  });
  $("cut-close").addEventListener("click", () => {
    setTool(page, false);
    setLine(page, null);
  });
  $("cut-fit").addEventListener("click", () => cut?.fit());
  $<HTMLInputElement>("cut-voids").addEventListener("change", (ev) => {
    if (!cut) return;
    cut.showVoids = (ev.target as HTMLInputElement).checked;
    cut.request();
  });
  const position = () => {
    const axis = $<HTMLSelectElement>("cut-axis").value === "x" ? "x" : "y";
    const l = axisLine(page, axis, Number($<HTMLInputElement>("cut-pos").value));
    if (l) setLine(page, l);
  };
  $("cut-apply").addEventListener("click", position);
  $("cut-pos").addEventListener("keydown", (ev) => {
    if ((ev as KeyboardEvent).key === "Enter") position();
  });

  // on the layer canvas: grab an end or the line, or (the tool) draw a new line; before the
  // layer view's pan (capture), which never sees a pointer the cut took
  const canvas = renderer.canvas;
  let drag: { what: "a" | "b" | "line"; id: number; from: Pt; line: Line; fresh: boolean } | null = null;
  const at = (ev: PointerEvent): [number, number] => {
    const r = canvas.getBoundingClientRect();
    return [ev.clientX - r.left, ev.clientY - r.top];
  };
  canvas.addEventListener(
    "pointerdown",
    (ev) => {
      if (!page.store.slice) return;
      const [x, y] = at(ev);
      let what = grab(page, x, y);
      const mm = renderer.toMm(x, y);
      const fresh = !what && state.tool;
      if (fresh) {
        state.line = { a: mm, b: mm };
        what = "b";
      }
      if (!what || !state.line) return;
      ev.stopImmediatePropagation();
      drag = { what, id: ev.pointerId, from: mm, line: { a: [...state.line.a], b: [...state.line.b] }, fresh };
      canvas.setPointerCapture(ev.pointerId);
    },
    { capture: true },
  );
  canvas.addEventListener(
    "pointermove",
    (ev) => {
      if (!drag || ev.pointerId !== drag.id) {
        if (!drag && state.line) canvas.classList.toggle("grab", grab(page, ...at(ev)) !== null);
        return;
      }
      ev.stopImmediatePropagation();
      const [x, y] = renderer.toMm(...at(ev));
      const l = drag.line;
      const dx = x - drag.from[0];
      const dy = y - drag.from[1];
      const next: Line =
        drag.what === "a" ? { a: [x, y], b: l.b } : drag.what === "b" ? { a: l.a, b: [x, y] } : { a: [l.a[0] + dx, l.a[1] + dy], b: [l.b[0] + dx, l.b[1] + dy] };
      state.line = next;
      renderer.request();
    },
    { capture: true },
  );
  const end = (ev: PointerEvent) => {
    if (!drag || ev.pointerId !== drag.id) return;
    ev.stopImmediatePropagation();
    const fresh = drag.fresh;
    drag = null;
    const l = checkLine(state.line);
    if (l) setLine(page, l, fresh || $("cut-panel").hidden === true);
    else setLine(page, null);
  };
  canvas.addEventListener("pointerup", end, { capture: true });
  canvas.addEventListener("pointercancel", end, { capture: true });

  // the cut canvas: wheel zoom, drag pan, double-click fit
  const cv = cut.canvas;
  cv.addEventListener(
    "wheel",
    (ev) => {
      ev.preventDefault();
      const r = cv.getBoundingClientRect();
      const dy = ev.deltaMode === 1 ? ev.deltaY * 16 : ev.deltaY;
      cut?.zoomAt(ev.clientX - r.left, ev.clientY - r.top, Math.exp(-dy * 0.0015));
    },
    { passive: false },
  );
  let pan: { x: number; y: number; id: number } | null = null;
  cv.addEventListener("pointerdown", (ev) => {
    pan = { x: ev.clientX, y: ev.clientY, id: ev.pointerId };
    cv.setPointerCapture(ev.pointerId);
    cv.classList.add("dragging");
  });
  cv.addEventListener("pointermove", (ev) => {
    if (!pan || ev.pointerId !== pan.id) return;
    cut?.panBy(ev.clientX - pan.x, ev.clientY - pan.y);
    pan.x = ev.clientX;
    pan.y = ev.clientY;
  });
  const stop = () => {
    pan = null;
    cv.classList.remove("dragging");
  };
  cv.addEventListener("pointerup", stop);
  cv.addEventListener("pointercancel", stop);
  cv.addEventListener("dblclick", () => cut?.fit());

  return {
    /** Sets the cut line `{a: [x, y], b: [x, y]}` (mm); false if it is refused. */
    set: (l: unknown): boolean => {
      const line = checkLine(l);
      if (line) setLine(page, line);
      return line !== null;
    },
    /** The cut's state: the line, layers with droplets, droplets, layers resolved by the
     *  core, voids, runs still out. */
    status: () => {
      let droplets = 0;
      let layers = 0;
      let voids = 0;
      for (const l of cut?.layers.values() ?? []) {
        droplets += l.near.length / 3;
        if (l.near.length) layers++;
        voids += (l.voids?.length ?? 0) / 3;
      }
      return { line: state.line, layers, droplets, resolved: state.resolved.size, voids, pending: state.queue.length + state.inFlight, error: state.error, view: cut ? { ...cut.view } : null };
    },
    setView: (v: { scale: number; ct: number; cz: number }) => {
      cut?.setView(v);
      cut?.request();
    },
    redraw: () => cut?.draw(),
  };
}

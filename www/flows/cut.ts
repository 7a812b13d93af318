// The vertical cut's runs (views/cut.ts draws the line and takes the pointer; canvas/cutrender.ts
// draws the section): droplets near the line come from the page's cache at once (binned once
// per layer and line: t, d, role); the part's section along the line and the 3D estimate's
// voids come from the workers (src/wasm/cut.rs), in runs of layers from the one shown outwards,
// a few at a time. The page sends the droplets near the line of the layers it holds; a layer it
// does not hold (evicted) is planned by the worker, which returns its droplets near the line:
// the page never fetches layers' full previews for the cut. A new line drops the runs not yet
// sent.

import { Cancelled } from "../core/client";
import { crossesBox, lineLength, type Line } from "../core/cutline";
import { grouped, records } from "../core/grouped";
import { NOT_SENT, type CutReply, type LayerData } from "../core/protocol";
import type { Slice } from "../core/store";
import type { CutLayer } from "../views/page";
import { dropletClass } from "../views/canvas/render";
import { writeCutLegend, writeCutStatus } from "../views/cut";
import type { Page } from "../views/page";
import { showError } from "./errors";

/** Layers per request to a worker. */
const RUN = 24;

interface State {
  /** The line the runs are for. */
  line: Line | null;
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

const state: State = { line: null, slice: null, gen: 0, queue: [], inFlight: 0, resolved: new Set(), binned: new Set(), error: null };

/** The footprint radius R of the analysis' footprint setting (disc: B/2; spread: B/√π). */
function radiusOf(s: Slice): number {
  return s.settings.footprint === "spread" ? s.dropletWidth / Math.sqrt(Math.PI) : s.dropletWidth / 2;
}

/** t, d, colour class (canvas/render.ts `dropletClass`) of a layer's droplets whose footprint
 *  (radius `radius`) the plane crosses, and x, y of those within `reach` of the line (sent to
 *  the core). */
function bin(layer: LayerData, l: Line, reach: number, radius: number): { near: Float64Array; xy: Float64Array } {
  const len = lineLength(l);
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
  const cut = page.cut;
  if (!s || !state.line) return false;
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
        if (gen === state.gen) take(page, r, from, to, flags, lo);
      })
      .catch((e) => {
        if (e instanceof Cancelled || gen !== state.gen) return;
        state.error = e instanceof Error ? e.message : String(e);
        showError(page, e);
      })
      .finally(() => {
        if (gen === state.gen) state.inFlight--;
        pump(page);
        updateCut(page);
      });
  }
}

/** A worker's reply for layers [from, to). */
function take(page: Page, r: CutReply, from: number, to: number, sent: Uint32Array, lo: number): void {
  const cut = page.cut;
  const byLayer = (flat: Float64Array, stride: number, value: (rec: Float64Array) => number[]) =>
    grouped(records(flat, stride), (rec) => rec[0], value);
  const spans = byLayer(r.spans, 3, (x) => [x[1], x[2]]);
  const voids = byLayer(r.voids, 4, (x) => [x[1], x[2], x[3]]);
  const planned = byLayer(r.droplets, 5, (x) => [x[1], x[2], dropletClass(x[3], x[4])]);
  const flat = (m: Map<number, number[][]>, i: number) => Float64Array.from((m.get(i) ?? []).flat());
  for (let i = from; i < to; i++) {
    const old = cut.layers.get(i);
    const near = sent[i - lo] === NOT_SENT ? flat(planned, i) : (old?.near ?? new Float64Array(0));
    const layer: CutLayer = { near, spans: flat(spans, i), voids: flat(voids, i) };
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
  page.cut.layers = new Map();
  page.cut.length = state.line ? lineLength(state.line) : 0;
}

/** Keeps the cut in step with the page: a new slice, layers that arrived, the layer shown. */
export function updateCut(page: Page): void {
  const cut = page.cut;
  if (!state.line) return;
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
  const pending = s.source === "stl" ? s.layers - state.resolved.size : 0;
  writeCutLegend(s.unitCount);
  writeCutStatus(s.source === "gco" ? " · voids need a model, not a .gco file" : pending > 0 ? ` · section of ${s.layers - pending} / ${s.layers} layers` : "", crossesNothing(s, state.line, pending, cut.layers.values()));
}

/** Whether the line misses every part: it passes beside the slice's box, or (once the core
 *  has every layer's section) no layer has a section or a droplet along it. A .gco file has
 *  no sections: its droplets decide once every layer was binned. */
function crossesNothing(s: Slice, line: Line, pending: number, layers: Iterable<CutLayer>): boolean {
  const b = s.info.bounds;
  const box = b ? { minX: b.min[0], minY: b.min[1], maxX: b.max[0], maxY: b.max[1] } : s.bbox;
  if (Number.isFinite(box.minX) && !crossesBox(line, box, s.dropletWidth)) return true;
  const complete = s.source === "stl" ? s.complete && pending === 0 : s.complete && state.binned.size === s.layers;
  if (!complete || s.layers === 0) return false;
  for (const l of layers) if (l.near.length || l.spans?.length) return false;
  return true;
}

/** Sets the cut line (null: no cut; views/cut.ts shows the panel); `refit` fits the cut's
 *  canvas to the new line. */
export function setCutLine(page: Page, line: Line | null, refit = true): void {
  state.line = line;
  if (!line) return;
  reset(page);
  updateCut(page);
  if (refit) {
    page.cut.touched = false;
    page.cut.fit();
  }
}

/** For the tests: the line, layers with droplets, droplets, layers resolved by the core,
 *  voids, runs still out, the last error and the cut canvas' view. */
export function cutStatus(page: Page) {
  let droplets = 0;
  let layers = 0;
  let voids = 0;
  for (const l of page.cut.layers.values()) {
    droplets += l.near.length / 3;
    if (l.near.length) layers++;
    voids += (l.voids?.length ?? 0) / 3;
  }
  return { line: state.line, layers, droplets, resolved: state.resolved.size, voids, pending: state.queue.length + state.inFlight, error: state.error, view: page.cut.cutView() };
}

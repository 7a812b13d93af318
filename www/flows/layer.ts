// The layer shown: the slider's layer on the canvas (and in the 3D view, the statistics), the
// layers fetched again from a worker when they were evicted, the overhang overlay's marks
// (asked of a worker per layer), and fitting the view to the part.

import { Cancelled } from "../core/client";
import type { Slice } from "../core/store";
import type { SettingName } from "../core/settings";
import { unitIndices, unitSetting } from "../core/units";
import { overhangsShown, showLayerNumber } from "../views/layer";
import type { Page } from "../views/page";
import { writeStats } from "../views/stats";
import { showError } from "./errors";

/** Shows layer `i` (clamped to the slice): the canvas, the slider, the 3D view, the figures;
 *  layers not held are fetched. */
export function show(page: Page, i: number): void {
  const { store, renderer } = page;
  const s = store.slice;
  if (!s || s.layers === 0) return;
  store.current = clampLayer(Number.isFinite(i) ? i : store.current, s.layers);
  const current = store.current;
  showLayerNumber(page);
  renderer.current = s.cache.get(current) ?? null;
  renderer.below = current > 0 ? (s.cache.get(current - 1) ?? null) : null;
  renderer.dropletWidth = s.dropletWidth;
  renderer.overhangs = renderer.showOverhangs ? (s.overhangs.get(current) ?? null) : null;
  if (renderer.showOverhangs && !renderer.overhangs) requestOverhangs(page, s, current);
  renderer.request();
  page.view3d.sync(page);
  writeStats(page);
  for (const k of [current, current - 1]) {
    if (k >= 0 && !s.cache.has(k) && s.complete && s.source === "stl") fetchPreview(page, s, k);
  }
  // the overlay needs the current layer's mask (evicted, or sliced without analysis)
  const shown = s.cache.get(current);
  if (renderer.showVoids && shown && !shown.mask && s.complete && s.source === "stl") fetchPreview(page, s, current);
}

/** The overhang rule's numbers for a slice: each unit's droplet width [B, B₁, …] and
 *  `overhang_limit`·B (mm), from the slice's settings, or a .gco file's header (the core's
 *  defaults where it says nothing). */
function overhangRule(page: Page, s: Slice): { widths: number[]; limitMm: number } | null {
  const header = s.gcodeFile?.header ?? {};
  const get = (k: SettingName) => {
    const v = Number(s.source === "gco" ? (header[k] ?? page.init?.defaults[k]) : s.settings[k]);
    return Number.isFinite(v) ? v : NaN;
  };
  const b = s.dropletWidth;
  const widths = unitIndices(s.unitCount).map((u) => (u === 0 ? b : s.layerHeight * get(unitSetting("droplet_aspect", u))));
  const limitMm = get("overhang_limit") * b;
  if (!(widths.every((w) => w > 0) && limitMm >= 0)) return null;
  return { widths, limitMm };
}

const overhangRequests = new Set<string>();

/** Asks a worker for the overhang overlay of layer `i` once it and the layer below are held. */
function requestOverhangs(page: Page, s: Slice, i: number): void {
  const layer = s.cache.get(i);
  const below = i > 0 ? s.cache.get(i - 1) : null;
  if (!layer?.units || (i > 0 && !below?.units)) return; // show() fetches them; asked again then
  const rule = overhangRule(page, s);
  const key = `${s.startedAt}:${i}`;
  if (!rule || overhangRequests.has(key)) return;
  overhangRequests.add(key);
  page.pool
    .unsupported({
      droplets: layer.droplets,
      units: layer.units,
      below: below ? { droplets: below.droplets, units: below.units } : null,
      ...rule,
    })
    .then((mask) => {
      if (page.store.slice !== s) return;
      s.overhangs.set(i, mask);
      if (i === page.store.current) show(page, i);
    })
    .catch((e) => {
      if (!(e instanceof Cancelled)) showError(page, e);
    })
    .finally(() => overhangRequests.delete(key));
}

/** The overhang overlay on or off (the checkbox, the legend, and the 3D view's tint). */
export function setShowOverhangs(page: Page, on: boolean): void {
  page.renderer.showOverhangs = on;
  overhangsShown(on);
  if (page.store.slice) show(page, page.store.current);
  else page.renderer.request();
  page.view3d.sync(page);
}

/** A layer index within [0, layers): rounded, clamped; 0 when it is not a number. */
export function clampLayer(i: number, layers: number): number {
  if (!Number.isFinite(i)) return 0;
  return Math.max(0, Math.min(layers - 1, Math.round(i)));
}

function fetchPreview(page: Page, s: Slice, k: number): void {
  const { store, pool, renderer } = page;
  if (store.previewRequests.has(k)) return;
  store.previewRequests.add(k);
  pool.preview(k, renderer.showVoids)
    .then((l) => {
      if (store.slice !== s) return;
      s.put(l, store.current);
      if (k === store.current || k === store.current - 1) show(page, store.current);
    })
    .catch((e) => {
      if (!(e instanceof Cancelled)) showError(page, e);
    })
    .finally(() => store.previewRequests.delete(k));
}

/** The part's bounds (the droplets' for a .gco file) fill the canvas (or the 3D view frames
 *  the plate and the part, when it is shown). */
export function fit(page: Page): void {
  if (page.view3d.active) return page.view3d.fit();
  const s = page.store.slice;
  if (!s) return;
  const b = s.info.bounds;
  page.store.viewTouched = false;
  page.renderer.fit(b ? { minX: b.min[0], minY: b.min[1], maxX: b.max[0], maxY: b.max[1] } : s.bbox);
}

// The layer view: the slider and its label, the canvas (render.ts) with zoom, pan and fit, the
// arrow keys, and the layers fetched again from a worker when they were evicted.

import { Cancelled } from "../client";
import { showError } from "../errors";
import type { Page } from "../page";
import type { Slice } from "../store";
import { $ } from "./dom";
import { writeStats } from "./stats";

const slider = () => $<HTMLInputElement>("layer");

export function layerLabel(page: Page): void {
  const s = page.store.slice;
  const current = page.store.current;
  const out = $("layer-label");
  if (!s || s.layers === 0) {
    out.textContent = "–";
    return;
  }
  const z = s.z[current];
  out.textContent = `Layer ${current + 1} / ${s.layers}` + (z !== undefined ? ` · z ${z.toFixed(2)} mm` : "");
}

/** Sets the slider's range for a slice of `layers` layers. */
export function setLayers(layers: number): void {
  slider().max = String(Math.max(0, layers - 1));
}

export function show(page: Page, i: number): void {
  const { store, renderer } = page;
  const s = store.slice;
  if (!s || s.layers === 0) return;
  store.current = clampLayer(Number.isFinite(i) ? i : store.current, s.layers);
  const current = store.current;
  slider().value = String(current);
  layerLabel(page);
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

/** The overhang rule's numbers for a slice: [B, B₁] and `overhang_limit`·B (mm), from the
 *  slice's settings, or a .gco file's header (the core's defaults where it says nothing). */
function overhangRule(page: Page, s: Slice): { widths: [number, number]; limitMm: number } | null {
  const header = s.gcodeFile?.header ?? {};
  const get = (k: string) => {
    const v = Number(s.source === "gco" ? (header[k] ?? page.init?.defaults[k]) : s.settings[k]);
    return Number.isFinite(v) ? v : NaN;
  };
  const b = s.dropletWidth;
  const b1 = s.layerHeight * get("unit1_droplet_aspect");
  const limitMm = get("overhang_limit") * b;
  if (!(b > 0 && b1 > 0 && limitMm >= 0)) return null;
  return { widths: [b, b1], limitMm };
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
  $<HTMLInputElement>("opt-overhangs").checked = on;
  $("legend-overhangs").hidden = !on;
  $("legend3d-overhang").hidden = !on;
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

/** Slider, buttons, keys, and the canvas' wheel zoom, drag pan and double-click fit. */
export function wireLayerView(page: Page): void {
  const { store, renderer } = page;
  const input = slider();
  input.addEventListener("input", () => show(page, Number(input.value)));
  $("btn-up").addEventListener("click", () => show(page, store.current + 1));
  $("btn-down").addEventListener("click", () => show(page, store.current - 1));
  $("btn-fit").addEventListener("click", () => fit(page));
  $<HTMLInputElement>("opt-travel").addEventListener("change", (ev) => {
    renderer.showTravel = (ev.target as HTMLInputElement).checked;
    $("legend-travel").hidden = !renderer.showTravel;
    renderer.request();
  });
  $<HTMLInputElement>("opt-below").addEventListener("change", (ev) => {
    renderer.showBelow = (ev.target as HTMLInputElement).checked;
    $("legend-below").hidden = !renderer.showBelow;
    renderer.request();
  });

  document.addEventListener("keydown", (ev) => {
    const t = ev.target as HTMLElement;
    if (t === input || t.closest("form, dialog") || t instanceof HTMLInputElement || t instanceof HTMLSelectElement) return;
    const step: Record<string, number> = { ArrowUp: 1, ArrowRight: 1, ArrowDown: -1, ArrowLeft: -1, PageUp: 10, PageDown: -10 };
    if (ev.key in step) show(page, store.current + step[ev.key]);
    else if (ev.key === "Home") show(page, 0);
    else if (ev.key === "End") show(page, store.slice ? store.slice.layers - 1 : 0);
    else if (ev.key === "f" || ev.key === "F") fit(page);
    else return;
    ev.preventDefault();
  });

  const canvas = renderer.canvas;
  canvas.addEventListener(
    "wheel",
    (ev) => {
      ev.preventDefault();
      const r = canvas.getBoundingClientRect();
      const dy = ev.deltaMode === 1 ? ev.deltaY * 16 : ev.deltaY;
      renderer.zoomAt(ev.clientX - r.left, ev.clientY - r.top, Math.exp(-dy * 0.0015));
      store.viewTouched = true;
    },
    { passive: false },
  );
  let drag: { x: number; y: number; id: number } | null = null;
  canvas.addEventListener("pointerdown", (ev) => {
    drag = { x: ev.clientX, y: ev.clientY, id: ev.pointerId };
    canvas.setPointerCapture(ev.pointerId);
    canvas.classList.add("dragging");
    canvas.focus();
  });
  canvas.addEventListener("pointermove", (ev) => {
    if (!drag || ev.pointerId !== drag.id) return;
    renderer.panBy(ev.clientX - drag.x, ev.clientY - drag.y);
    drag.x = ev.clientX;
    drag.y = ev.clientY;
    store.viewTouched = true;
  });
  const end = () => {
    drag = null;
    canvas.classList.remove("dragging");
  };
  canvas.addEventListener("pointerup", end);
  canvas.addEventListener("pointercancel", end);
  canvas.addEventListener("dblclick", () => fit(page));
  renderer.onDraw = () => {
    $("zoom").textContent = `${renderer.view.scale >= 10 ? Math.round(renderer.view.scale) : renderer.view.scale.toFixed(1)} px/mm`;
  };
}

/** Travel moves drawn or not (a preview link says which), with the checkbox and the legend. */
export function setShowTravel(page: Page, on: boolean): void {
  page.renderer.showTravel = on;
  $<HTMLInputElement>("opt-travel").checked = page.renderer.showTravel;
  $("legend-travel").hidden = !page.renderer.showTravel;
}

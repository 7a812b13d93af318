// The layer view: the slider and its label, the canvas (canvas/render.ts) with zoom, pan and
// fit, the arrow keys. The layer shown and its fetching: flows/layer.ts.

import { wirePanZoom } from "./canvas/panzoom";
import { $ } from "./dom";
import type { Page } from "./page";

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

/** The slider and the label at the layer shown. */
export function showLayerNumber(page: Page): void {
  slider().value = String(page.store.current);
  layerLabel(page);
}

/** The overhang overlay's checkbox and legends (the layer canvas' and the 3D view's). */
export function overhangsShown(on: boolean): void {
  $<HTMLInputElement>("opt-overhangs").checked = on;
  $("legend-overhangs").hidden = !on;
  $("legend3d-overhang").hidden = !on;
}

/** Sets the slider's range for a slice of `layers` layers. */
export function setLayers(layers: number): void {
  slider().max = String(Math.max(0, layers - 1));
}

/** Slider, buttons, keys, and the canvas' wheel zoom, drag pan and double-click fit. */
export function wireLayerView(page: Page): void {
  const { store, renderer } = page;
  const { show, fit } = page.actions;
  const input = slider();
  input.addEventListener("input", () => show(Number(input.value)));
  $("btn-up").addEventListener("click", () => show(store.current + 1));
  $("btn-down").addEventListener("click", () => show(store.current - 1));
  $("btn-fit").addEventListener("click", () => fit());
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
    if (ev.key in step) show(store.current + step[ev.key]);
    else if (ev.key === "Home") show(0);
    else if (ev.key === "End") show(store.slice ? store.slice.layers - 1 : 0);
    else if (ev.key === "f" || ev.key === "F") fit();
    else return;
    ev.preventDefault();
  });

  wirePanZoom(renderer, fit, () => (store.viewTouched = true));
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

/** The overlay checkboxes by name (the layer view's toggles). */
export const OVERLAYS = { travel: "opt-travel", below: "opt-below", voids: "opt-voids", overhangs: "opt-overhangs" } as const;

/** Turns an overlay on or off as its checkbox would (its own handler does the rest). */
export function setOverlay(name: keyof typeof OVERLAYS, on: boolean): void {
  const box = $<HTMLInputElement>(OVERLAYS[name]);
  if (box.checked === on) return;
  box.checked = on;
  box.dispatchEvent(new Event("change"));
}

// Page wiring only: events -> worker pool (client.ts) -> store (store.ts) -> views (views/).
// The runs of the workers are in flows.ts, opening files and links in open.ts, the figures
// of a slice in figures.ts.

import { Cancelled, MAX_WORKERS, Pool } from "./client";
import { showError } from "./errors";
import { analyseVoids, cancel, download, fixUnits, startSlice } from "./flows";
import { SettingsForm } from "./form";
import { PART_KEYS } from "./job";
import { addParts, relayout } from "./jobflows";
import { openFiles, openLink, openSample } from "./open";
import type { Page } from "./page";
import { Renderer, type View } from "./render";
import { cacheBudgetBytes, Store } from "./store";
import { hideBanner } from "./views/banner";
import { updateButtons } from "./views/controls";
import { $ } from "./views/dom";
import { wireCalibrate } from "./views/calibrate";
import { wireCut } from "./views/cut";
import { setShowOverhangs, show, wireLayerView } from "./views/layer";
import { wirePlot } from "./views/plot";
import { registerOffline } from "./offline";
import { share } from "./views/share";
import { setState } from "./views/status";
import { wirePartDrag } from "./views/partdrag";
import { PartsPanel } from "./views/parts";
import { View3DPanel, wireView3D } from "./views/view3d";

/** Tuning through the query string (used by the tests): `?workers=3&cache=2` (MB). */
const query = new URLSearchParams(location.search);

/** Most workers `?workers=N` may ask for: each holds its own copy of the model, so not more
 *  than the cores (but 4 even on fewer cores, which the tests use) and never more than 8. */
const WORKERS_MAX = Math.min(MAX_WORKERS, Math.max(4, navigator.hardwareConcurrency || 1));

/** `?workers=N`: clamped to 1 … [[WORKERS_MAX]]; absent, empty or not a number: the default. */
function workersAsked(): number | null {
  const raw = query.get("workers");
  const n = raw === null || raw.trim() === "" ? NaN : Math.round(Number(raw));
  return Number.isFinite(n) ? Math.max(1, Math.min(WORKERS_MAX, n)) : null;
}

const asked = workersAsked();
const page: Page = {
  store: new Store(cacheBudgetBytes(query)),
  pool: asked === null ? new Pool() : new Pool(asked),
  renderer: new Renderer($<HTMLCanvasElement>("view")),
  view3d: new View3DPanel($("view3d")),
  parts: null as unknown as PartsPanel,
  onUnitFix: (factor) => fixUnits(page, factor),
};
(page as { parts: PartsPanel }).parts = new PartsPanel(page);
const { store, pool, renderer } = page;
const error = (e: unknown) => showError(page, e);

let cutHooks: ReturnType<typeof wireCut> | null = null;

function wire(): void {
  $("btn-sample").addEventListener("click", () => void openSample(page));
  $<HTMLInputElement>("file-input").addEventListener("change", (ev) => {
    const input = ev.target as HTMLInputElement;
    const files = [...(input.files ?? [])];
    input.value = "";
    if (files.length) void openFiles(page, files);
  });
  $<HTMLInputElement>("add-input").addEventListener("change", (ev) => {
    const input = ev.target as HTMLInputElement;
    const files = [...(input.files ?? [])];
    input.value = "";
    if (files.length) void addParts(page, files);
  });
  page.parts.wire();
  $("btn-download").addEventListener("click", () => void download(page));
  $("btn-share").addEventListener("click", () => void share(page).catch(error));
  $("btn-slice").addEventListener("click", () => void startSlice(page));
  $("btn-reset").addEventListener("click", () => page.form!.reset());
  $("btn-cancel").addEventListener("click", () => cancel(page));
  $("banner-close").addEventListener("click", hideBanner);
  // the form is never submitted (Enter slices, below); no inline handler: the page's CSP
  $("settings").addEventListener("submit", (ev) => ev.preventDefault());
  $("settings").addEventListener("keydown", (ev) => {
    if ((ev as KeyboardEvent).key === "Enter" && store.job) {
      ev.preventDefault();
      void startSlice(page);
    }
  });

  wireLayerView(page);
  wireView3D(page);
  cutHooks = wireCut(page);
  wirePartDrag(page);
  wirePlot(page, (i) => show(page, i));
  wireCalibrate(page);
  $<HTMLInputElement>("opt-voids").addEventListener("change", (ev) => {
    renderer.showVoids = (ev.target as HTMLInputElement).checked;
    $("legend-voids").hidden = !renderer.showVoids;
    if (store.slice) show(page, store.current);
    if (renderer.showVoids && store.slice) void analyseVoids(page, store.slice);
    renderer.request();
  });
  $<HTMLInputElement>("opt-overhangs").addEventListener("change", (ev) => setShowOverhangs(page, (ev.target as HTMLInputElement).checked));
  $("btn-worst-overhang").addEventListener("click", () => {
    const worst = store.slice?.figures.worstOverhang;
    if (worst) show(page, worst.index);
  });
  // the support switch sets the setting `support` (the Support group has its details)
  $<HTMLInputElement>("opt-support").addEventListener("change", (ev) => {
    const form = page.form;
    if (!form) return;
    form.set({ support: (ev.target as HTMLInputElement).checked ? "unit1" : "off" });
    updateButtons(page);
  });
  $("btn-worst").addEventListener("click", () => {
    const worst = store.slice?.figures.worst;
    if (worst) show(page, worst.index);
  });

  // drag and drop anywhere on the page
  const overlay = $("drop-overlay");
  let depth = 0;
  window.addEventListener("dragenter", (ev) => {
    if (!ev.dataTransfer?.types.includes("Files")) return;
    depth++;
    overlay.hidden = false;
  });
  window.addEventListener("dragleave", () => {
    depth = Math.max(0, depth - 1);
    if (depth === 0) overlay.hidden = true;
  });
  window.addEventListener("dragover", (ev) => ev.preventDefault());
  window.addEventListener("drop", (ev) => {
    ev.preventDefault();
    depth = 0;
    overlay.hidden = true;
    const files = [...(ev.dataTransfer?.files ?? [])];
    if (files.length) void openFiles(page, files);
  });

  window.addEventListener("error", (ev) => error(ev.error ?? ev.message));
  window.addEventListener("unhandledrejection", (ev) => {
    if (!(ev.reason instanceof Cancelled)) error(ev.reason);
  });
}

// hooks for the browser tests
declare global {
  interface Window {
    dropslice: unknown;
  }
}
window.dropslice = {
  status: () => {
    const slice = store.slice;
    return {
      state: document.body.dataset.state,
      layers: slice?.layers ?? 0,
      done: slice?.done ?? 0,
      complete: slice?.complete ?? false,
      layer: store.current,
      droplets: slice?.droplets ?? 0,
      counts: slice ? { ...slice.figures.totals } : null,
      /** Unit 1's droplets (support and unit-1 parts; a .gco file's after T1). */
      unit1: slice?.figures.unit1.droplets ?? 0,
      worstOverhang: slice?.figures.worstOverhang?.index ?? null,
      unsupportedArea: slice?.figures.unsupportedArea ?? null,
      /** The overhang overlay of the layer on the canvas: droplets marked (null: none yet). */
      overhangsMarked: renderer.overhangs ? renderer.overhangs.reduce((a, v) => a + v, 0) : null,
      layerDroplets: slice?.counts[store.current] ?? null,
      view: { ...renderer.view },
      name: slice?.name ?? null,
      workers: pool.size,
      /** Seconds from the file chosen to every layer's G-code ready (the last finished slice). */
      seconds: slice?.seconds ?? null,
      cached: slice?.cache.size ?? 0,
      voids: renderer.showVoids,
      analysed: slice?.analysed ?? 0,
      worst: slice?.figures.worst?.index ?? null,
      /** Whether the layer on the canvas carries its void mask. */
      masked: Boolean(renderer.current?.mask),
      /** Index of the layer on the canvas (null while it is being fetched). */
      shown: renderer.current?.index ?? null,
    };
  },
  crash: () => pool.crash().catch(error),
  /** Draws now (synchronously), for timing. */
  redraw: () => renderer.draw(),
  setView: (v: View) => {
    renderer.view = { ...v };
    store.viewTouched = true;
    renderer.request();
  },
  show: (i: number) => show(page, i),
  /** Per layer of the slice: support droplets, unit-1 droplets (null: not in yet). */
  layerUnits: () => store.slice?.counts.map((c) => (c ? [c.support ?? 0, c.unit1 ?? 0] : null)) ?? [],
  /** The 3D tab: draws it now and returns {parts, selected, slice, frames, width, height}
   *  (null until the tab was first opened). Its pixels: the canvas in #view3d. */
  view3d: () => page.view3d.testState(),
  /** The vertical cut (views/cut.ts): set(line), status(), setView(v), redraw(). */
  cut: () => cutHooks,
  /** The build job: its parts (specs), the core's layout and the selected part's id. */
  job: () => {
    const job = store.job;
    if (!job) return null;
    return { name: job.name, parts: job.parts.map((p) => ({ id: p.id, ...p.spec, mesh: p.mesh ? p.mesh.positions.length / 9 : 0 })), layout: job.layout, selected: job.selected };
  },
};

async function main(): Promise<void> {
  setState("loading");
  wire();
  try {
    page.init = await pool.init();
  } catch (e) {
    error(e);
    return;
  }
  $("version").textContent = page.init.version;
  // the plate's settings lay the job out again (at most every 200 ms while typing)
  let plateTimer = 0;
  const plate = () => JSON.stringify(["plate_x", "plate_y", "part_spacing"].map((k) => page.form?.get(k)));
  let lastPlate = "";
  page.form = new SettingsForm(
    $("settings"),
    page.init.schema,
    () => {
      updateButtons(page);
      if (plate() !== lastPlate) {
        lastPlate = plate();
        clearTimeout(plateTimer);
        plateTimer = window.setTimeout(() => void relayout(page), 200);
      }
    },
    PART_KEYS,
  );
  lastPlate = plate();
  updateButtons(page);
  if (!(await openLink(page))) await openSample(page);
}

registerOffline();
void main();

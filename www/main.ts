// Page wiring only: the page's one instance (core/ store and worker pool, views/ canvases and
// panels), the actions the views ask for wired to their flows (flows/), the page's own events
// (buttons, drag and drop) to flows, the service worker (pwa/), and the tests' hooks.

import { Cancelled, MAX_WORKERS, Pool } from "./core/client";
import { checkLine } from "./core/cutline";
import { History, sameSnapshot } from "./core/history";
import { jobOffPlate } from "./core/plate";
import { cacheBudgetBytes, Store } from "./core/store";
import type { View } from "./core/view";
import { cutStatus, setCutLine, updateCut } from "./flows/cut";
import { showError } from "./flows/errors";
import { addParts, applyOrientation, arrangeAll, cancelOrient, duplicatePart, editParts, ensureMeshes, layFlat, movePart, orientations, relayout, removePart, saveJob, selectPart } from "./flows/job";
import { deleteProfile, exportProfile, importProfile, renameProfile, saveProfile, showProfiles, useProfile } from "./flows/profiles";
import { redo, undo } from "./flows/history";
import { resetSettings, settingsChanged, whenRecorded } from "./flows/record";
import { fit, setShowOverhangs, show } from "./flows/layer";
import { openFiles, openLink, openSample } from "./flows/open";
import { holdJobForLink, initPersist, jobChanged, leavingLoses, pausePersist, persistStatus, restoreJob, startOver } from "./flows/persist";
import { applyRemembered, holdForLink, loadRemembered, saveNow, saveSoon, settingsTouched } from "./flows/remember";
import { analyseVoids, cancel, download, fixUnits, startSlice } from "./flows/slice";
import { registerOffline } from "./pwa/offline";
import { hideBanner } from "./views/banner";
import { wireCalibrate } from "./views/calibrate";
import { CutRenderer } from "./views/canvas/cutrender";
import { Renderer } from "./views/canvas/render";
import { supportOn, updateButtons } from "./views/controls";
import { setLine, wireCut } from "./views/cut";
import { $, wireSkipLinks } from "./views/dom";
import { SettingsForm } from "./views/form";
import { wireKeys } from "./views/keys";
import { OVERLAYS, wireLayerView } from "./views/layer";
import { wireNotices } from "./views/notices";
import type { Actions, Page, PartsView } from "./views/page";
import { wirePartDrag } from "./views/partdrag";
import { PartsPanel } from "./views/parts";
import { wireProfiles } from "./views/profiles";
import { wirePlot } from "./views/plot";
import { share } from "./views/share";
import { wireShortcuts } from "./views/shortcuts";
import { setState } from "./views/status";
import { View3DPanel, wireView3D } from "./views/view3d/panel";
import { wirePersistNotice } from "./views/persist";

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
/** What the views ask for, each a flow of the page. */
const actions: Actions = {
  show: (i) => show(page, i),
  fit: () => fit(page),
  error: (e) => showError(page, e),
  selectPart: (id) => selectPart(page, id),
  editParts: (edits) => editParts(page, edits),
  movePart: (id, copy, dx, dy) => movePart(page, id, copy, dx, dy),
  layFlat: (id) => void layFlat(page, id),
  orient: (id) => orientations(page, id),
  applyOrientation: (id, o) => applyOrientation(page, id, o),
  cancelOrient: () => (page.store.busy ? cancel(page) : cancelOrient(page)),
  profileSave: (name, kind, unit) => saveProfile(page, name, kind, unit),
  profileUse: (name, unit) => useProfile(page, name, unit),
  profileRename: (name, to) => renameProfile(page, name, to),
  profileDelete: (name) => deleteProfile(page, name),
  profileExport: (name) => exportProfile(page, name),
  profileImport: (file) => void importProfile(page, file),
  duplicatePart: (id) => duplicatePart(page, id),
  removePart: (id) => removePart(page, id),
  arrangeAll: () => arrangeAll(page),
  saveJob: () => saveJob(page),
  unitFix: (factor) => fixUnits(page, factor),
  calibrate: (request) => page.pool.calibrate(request),
  overhangFace: (settings) => page.pool.overhangFace(settings),
  meshes: () => void ensureMeshes(page),
  setCutLine: (line, refit) => setCutLine(page, line, refit),
  updateCut: () => updateCut(page),
  cutLine: () => cutStatus(page).line,
  undo: () => void undo(page).catch(error),
  redo: () => void redo(page).catch(error),
  settingsEdited: () => {
    settingsChanged(page);
    saveSoon(page);
  },
};
const page: Page = {
  store: new Store(cacheBudgetBytes(query)),
  pool: asked === null ? new Pool() : new Pool(asked),
  renderer: new Renderer($<HTMLCanvasElement>("view")),
  cut: new CutRenderer($<HTMLCanvasElement>("cut-view")),
  view3d: new View3DPanel($("view3d")),
  parts: null as unknown as PartsView,
  actions,
  history: new History(sameSnapshot),
};
(page as { parts: PartsView }).parts = new PartsPanel(page);
// every recorded change is kept in the browser (flows/persist.ts)
whenRecorded(jobChanged);
const { store, pool, renderer } = page;
const error = actions.error;

function wire(): void {
  $("btn-sample").addEventListener("click", () => void openSample(page));
  // the file pickers' buttons (real buttons: Tab reaches them, Enter and Space open the picker)
  $("btn-open").addEventListener("click", () => $<HTMLInputElement>("file-input").click());
  $("btn-add").addEventListener("click", () => $<HTMLInputElement>("add-input").click());
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
  wireProfiles(page);
  $("btn-download").addEventListener("click", () => void download(page));
  $("btn-share").addEventListener("click", () => void share(page).catch(error));
  $("btn-slice").addEventListener("click", () => void startSlice(page));
  $("btn-reset").addEventListener("click", () => resetSettings(page));
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
  wireKeys(page);
  wireNotices(page);
  wireView3D(page);
  wireCut(page);
  wirePartDrag(page);
  wirePlot(page, actions.show);
  wireShortcuts();
  wireSkipLinks();
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
    form.set({ support: (ev.target as HTMLInputElement).checked ? supportOn() : "off" });
    updateButtons(page);
    actions.settingsEdited();
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

  // remembered: the overlays and the mode as they change, everything when the page is left
  for (const id of Object.values(OVERLAYS)) $(id).addEventListener("change", () => saveSoon(page));
  for (const id of ["mode-layer", "mode-3d"]) $(id).addEventListener("click", () => saveSoon(page));
  window.addEventListener("pagehide", () => saveNow(page));
  // leaving asks first when the job on screen is not the one kept in the browser (a write
  // pending, too big to keep, no store): flows/persist.ts
  wirePersistNotice(() => void startOver(page).catch(error));
  window.addEventListener("beforeunload", (ev) => {
    if (!leavingLoses(page)) return;
    ev.preventDefault();
    ev.returnValue = "";
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
      /** The units shown, and each one's droplets (its parts' and, for the unit that prints
       *  it, the support's). */
      units: slice?.unitCount ?? null,
      unitDroplets: slice?.figures.units(slice.unitCount).map((u) => u.droplets) ?? [],
      worstOverhang: slice?.figures.worstOverhang?.index ?? null,
      unsupportedArea: slice?.figures.unsupportedArea ?? null,
      /** The overhang overlay of the layer on the canvas: droplets marked (null: none yet). */
      overhangsMarked: renderer.overhangs ? renderer.overhangs.reduce((a, v) => a + v, 0) : null,
      layerDroplets: slice?.counts[store.current] ?? null,
      view: { ...renderer.view },
      name: slice?.name ?? null,
      workers: pool.size,
      /** Workers started so far (a slice's cancel replaces all, an Orient's the job worker). */
      workersStarted: Pool.started,
      /** Requests the job worker has not answered yet. */
      jobWorkerLoad: pool.jobWorkerLoad,
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
  redraw: () => renderer.drawNow(),
  setView: (v: View) => {
    renderer.view = { ...v };
    store.viewTouched = true;
    renderer.request();
  },
  show: (i: number) => show(page, i),
  /** Per layer of the slice: support droplets, unit-1 droplets (null: not in yet). */
  layerUnits: () => store.slice?.counts.map((c) => (c ? [c.support ?? 0, ...(c.units ?? []).slice(1)] : null)) ?? [],
  /** The 3D tab: draws it now and returns {parts, selected, slice, frames, width, height}
   *  (null until the tab was first opened). Its pixels: the canvas in #view3d. */
  view3d: () => page.view3d.testState(),
  /** The 3D camera {position, target} (plate mm; null before the view was made). */
  camera: () => page.view3d.camera(),
  /** The vertical cut (views/cut.ts, flows/cut.ts): set(line), status(), setView(v), redraw(). */
  cut: () => ({
    /** Sets the cut line `{a: [x, y], b: [x, y]}` (mm); false if it is refused. */
    set: (l: unknown): boolean => {
      const line = checkLine(l);
      if (line) setLine(page, line);
      return line !== null;
    },
    /** The cut's state: the line, layers with droplets, droplets, layers resolved by the
     *  core, voids, runs still out. */
    status: () => cutStatus(page),
    setView: (v: { scale: number; ct: number; cz: number }) => {
      page.cut.setView(v);
      page.cut.request();
    },
    redraw: () => page.cut.drawNow(),
  }),
  /** The build job: its parts (specs), the core's layout and the selected part's id. */
  job: () => {
    const job = store.job;
    if (!job) return null;
    return {
      name: job.name,
      parts: job.parts.map((p) => ({ id: p.id, ...p.spec, mesh: (job.meshOf(p)?.positions.length ?? 0) / 9 })),
      layout: job.layout,
      selected: job.selected,
      /** Instances off the plate: {part (index), copy, message}. */
      offPlate: jobOffPlate(job, page.form?.values()),
    };
  },
  /** What Undo and Redo would undo and redo (null: nothing). */
  history: () => ({ undo: page.history.undoLabel, redo: page.history.redoLabel, edited: store.edited }),
  /** The job kept in the browser: {state, cap, link, leavingLoses}. */
  persist: () => ({ ...persistStatus(), leavingLoses: leavingLoses(page) }),
  /** Holds the job's writes (they stay pending) until released. */
  persistPause: (on: boolean) => pausePersist(page, on),
  /** The history's snapshots: how many, and the bytes of typed arrays they reach that the
   *  page's job on screen does not (display meshes kept alive by undo). */
  historyBytes: () => historyBytes(),
};

/** Bytes of the ArrayBuffers reachable from the history's snapshots (past, present, future)
 *  but not from the job on screen: what undo alone keeps alive. */
function historyBytes(): { snapshots: number; bytes: number } {
  const reach = (roots: unknown[]): Set<ArrayBufferLike> => {
    const seen = new Set<unknown>();
    const buffers = new Set<ArrayBufferLike>();
    const stack = [...roots];
    while (stack.length) {
      const v = stack.pop();
      if (typeof v !== "object" || v === null || seen.has(v)) continue;
      seen.add(v);
      if (ArrayBuffer.isView(v)) buffers.add(v.buffer);
      else if (v instanceof ArrayBuffer) buffers.add(v);
      else if (v instanceof Blob) continue;
      else if (v instanceof Map) for (const [k, x] of v) stack.push(k, x);
      else if (v instanceof Set) for (const x of v) stack.push(x);
      else for (const x of Object.values(v)) stack.push(x);
    }
    return buffers;
  };
  const snaps = page.history.snapshots();
  const live = reach([store.job]);
  let bytes = 0;
  for (const b of reach(snaps)) if (!live.has(b)) bytes += b.byteLength;
  return { snapshots: snaps.length, bytes };
}

async function main(): Promise<void> {
  setState("loading");
  initPersist(query);
  wire();
  try {
    page.init = await pool.init();
  } catch (e) {
    error(e);
    return;
  }
  $("version").textContent = page.init.version;
  // the settings the plate's layout reads (marked `layout` in the core's table) lay the job
  // out again (at most every 200 ms while typing)
  let plateTimer = 0;
  const layoutSettings = page.init.schema.filter((s) => s.layout).map((s) => s.name);
  const plate = () => JSON.stringify(layoutSettings.map((k) => page.form?.get(k)));
  let lastPlate = "";
  page.form = new SettingsForm(
    $("settings"),
    page.init.schema,
    () => {
      updateButtons(page);
      settingsChanged(page);
      settingsTouched();
      saveSoon(page);
      if (plate() !== lastPlate) {
        lastPlate = plate();
        clearTimeout(plateTimer);
        plateTimer = window.setTimeout(() => void relayout(page), 200);
      }
    },
  );
  // a preview link in the address, else the job kept from last time with the settings and the
  // view remembered, else the sample part with the default settings (a remembered setting
  // never makes a first visit's sample slow) and the remembered view
  const remembered = loadRemembered(page);
  showProfiles(page);
  updateButtons(page);
  // a link's settings and job are shown, not kept over the visitor's own until they edit
  const linked = location.hash.length > 1;
  holdForLink(linked);
  holdJobForLink(linked);
  if (linked && remembered) applyRemembered(page, { settings: {}, view: remembered.view });
  const fromLink = linked && (await openLink(page));
  if (!fromLink) {
    holdForLink(false);
    holdJobForLink(false);
    if (!(await restoreJob(page, remembered))) {
      if (remembered) applyRemembered(page, { settings: {}, view: remembered.view });
      await openSample(page, { layer: remembered?.view.layer ?? undefined });
    }
  }
  lastPlate = plate();
}

registerOffline();
void main();

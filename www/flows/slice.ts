// The runs of the workers, each a plain async function of the page (its store and its pool):
// a slice, the analysis pass over a finished slice, reading a .gco file, cancel, and the
// G-code's assembly for download. Opening files and links: open.ts.

import { Cancelled, SliceError } from "../core/client";
import type { GcodeParseResult } from "../core/protocol";
import type { View } from "../core/view";
import { restoreModel, showError } from "./errors";
import type { Page } from "../views/page";
import { jobSettings } from "../core/job";
import { editParts } from "./job";
import { record } from "./record";
import { undoNotice } from "../views/notices";
import type { Slice, SlicedJob } from "../core/store";
import { recordSupport } from "../core/supportcolumns";
import { errorBanner, hideBanner, showBanner, TITLES } from "../views/banner";
import { sliceState, updateButtons } from "../views/controls";
import { jobOffPlate } from "../core/plate";
import { saveGcode } from "../views/download";
import { layerLabel, setLayers } from "../views/layer";
import { clampLayer, show } from "./layer";
import { showModel, writeStats } from "../views/stats";
import { progress, setState } from "../views/status";

export interface Target {
  layer?: number;
  view?: View;
  /** Shown once the slice has started (a slice hides the banner): about the link that asked
   *  for it. */
  notice?: { title: string; message: string; tone?: "error" | "info" };
}

/** While the workers run, the progress and the figures are redrawn at most this often: each
 *  redraw costs style, layout and paint, and with few cores that time is taken from slicing. */
const BUSY_REDRAW_MS = 150;

/** Runs `update` in the next task when the last such redraw is [[BUSY_REDRAW_MS]] old (the
 *  first layer moves the bar at once, however fast the slice), else once at the end of that
 *  interval for all calls until then, unless the run `gen` has ended by then (the page is
 *  then drawn by whatever ended it). */
function whileBusy(page: Page, gen: number, update: () => void): void {
  const store = page.store;
  const pending = store.busyRedraw !== null;
  store.busyRedraw = { gen, update };
  if (pending) return;
  const run = () => {
    const r = store.busyRedraw;
    store.busyRedraw = null;
    if (r && r.gen === store.generation && store.busy) {
      store.busyRedrawAt = performance.now();
      r.update();
      // the layout now, in this task, not in the next frame's (where it joined the canvas'
      // draw, the paint and the commit in one task of 40–60 ms)
      void document.documentElement.offsetHeight;
    }
  };
  // in a task of its own, not in the worker's message (a longer task for the page's thread)
  setTimeout(run, Math.max(0, store.busyRedrawAt + BUSY_REDRAW_MS - performance.now()));
}

function settingsProblem(page: Page): boolean {
  const form = page.form!;
  const errors = form.errors();
  if (errors.length === 0) return false;
  showBanner(TITLES.setting, `Fix ${errors.map((e) => `${e.name.replace(/_/g, " ")} (${e.message})`).join(", ")} before slicing.`);
  form.focusFirstError();
  setState("error");
  return true;
}

function cancelRunning(page: Page): void {
  if (page.store.busy) {
    page.pool.cancel();
    page.store.busy = false;
  }
}

/** Slices the current job (its parts as they are now, the form's settings). */
export async function startSlice(page: Page, target: Target = {}): Promise<void> {
  const { store, pool, renderer } = page;
  const form = page.form!;
  const job = store.job;
  if (!job || job.parts.length === 0) return;
  if (settingsProblem(page)) return;
  // a job is sliced only when it fits: every part on the plate
  const off = jobOffPlate(job, form.values());
  if (off.length || !job.layout) {
    if (off.length) {
      showBanner("A part does not fit the plate.", off.map((o) => o.message).join(" "));
      // the next layout the core takes (the part turned, scaled or moved) hides it
      document.getElementById("banner")!.dataset.layout = "1";
    }
    setState("error");
    updateButtons(page);
    return;
  }
  cancelRunning(page);
  hideBanner();
  if (target.notice) showBanner(target.notice.title, target.notice.message, target.notice.tone, true);
  const gen = ++store.generation;
  const values = form.values();
  const settings = jobSettings(values);
  const refs = job.refs();
  const sliced: SlicedJob = { refs, file: job.file(settings), sha256: refs.map((r) => job.models.get(r.name)?.sha256 ?? "") };
  const key = job.key(settings);
  const name = job.name;
  // B is the core's (JobInfo.droplet_width, once the model is open)
  const s = store.newSlice("stl", name, NaN, Number(values.layer_height), values, sliced);
  s.key = key;
  if (store.fileChosenAt !== null) s.startedAt = store.fileChosenAt;
  store.fileChosenAt = null;
  const before = store.slice?.job ?? null;
  const sameModel = before !== null && before.sha256.join() === sliced.sha256.join() && !sliced.sha256.includes("");
  store.busy = true;
  setState("slicing");
  progress(0, `Reading ${name}…`);
  updateButtons(page);
  try {
    // the bar and the figures in one throttled redraw (one layout and paint for both)
    const redraw = () => {
      if (s.done < s.layers) progress(s.done / Math.max(1, s.layers));
      writeStats(page);
    };
    const figuresChanged = () => {
      if (store.slice === s && gen === store.generation) whileBusy(page, gen, redraw);
    };
    await pool.slice(refs, sliced.file, {
      opened: (r) => {
        if (gen !== store.generation) return;
        s.open(r.layers, r.info);
        if (typeof r.info.droplet_width === "number") s.dropletWidth = r.info.droplet_width;
        store.slice = s;
        setLayers(r.layers);
        progress(0);
        showModel(name);
        const wanted = target.layer ?? (sameModel ? store.current : Math.floor((r.layers - 1) * 0.3));
        store.current = clampLayer(wanted, r.layers);
        if (target.view) {
          // the renderer keeps any view within its limits
          renderer.view = { ...target.view };
          store.viewTouched = true;
        } else if (!sameModel || !store.viewTouched) {
          store.viewTouched = false;
          const b = r.info.bounds;
          renderer.fit(b ? { minX: b.min[0], minY: b.min[1], maxX: b.max[0], maxY: b.max[1] } : null);
        }
        show(page, store.current);
      },
      layer: (l) => {
        if (gen !== store.generation) return;
        s.put(l, store.current);
        recordSupport(s, l, s.dropletWidth, s.layerHeight);
        const current = store.current;
        // the layer shown and the one below it: drawn once both have arrived (a draw costs)
        const arrived = (k: number) => k < 0 || s.counts[k] !== undefined;
        if ((l.index === current || l.index === current - 1) && arrived(current) && arrived(current - 1)) show(page, current);
        // the last layer shows 100 % at once; before it the bar and figures now and then
        if (s.done === s.layers) progress(1);
        else whileBusy(page, gen, redraw);
      },
      unit: (u) => {
        if (gen !== store.generation) return;
        s.addUnit(u);
        s.figures.refresh(pool, figuresChanged).catch(() => {
          // the final refresh below reports what went wrong
        });
      },
    }, renderer.showVoids);
    if (gen !== store.generation) return;
    // the core's figures of every unit, before the slice counts as done
    await s.figures.refresh(pool, figuresChanged);
    if (gen !== store.generation) return;
    s.complete = true;
    s.seconds = (performance.now() - s.startedAt) / 1000;
    store.busy = false;
    progress(null);
    if (!store.viewTouched && !s.info.bounds) renderer.fit(s.bbox);
    show(page, store.current);
    setState("done");
    const nothing = s.figures.nothingToPrint;
    if (nothing) errorBanner(new SliceError(nothing.kind, nothing.message));
    // the overlay was turned on during a slice made without analysis
    if (renderer.showVoids && s.analysed < s.layers) void analyseVoids(page, s);
  } catch (e) {
    if (gen !== store.generation) return;
    store.busy = false;
    progress(null);
    if (e instanceof Cancelled) {
      setState("cancelled");
      showBanner("Slicing cancelled.", "Change the settings or open another file, then slice again.", "info");
    } else {
      // the slice broke half-way: nothing of it can be downloaded
      if (store.slice === s) dropSlice(page);
      showError(page, e);
    }
  } finally {
    if (gen === store.generation) updateButtons(page);
  }
}

/** Re-plans and analyses every layer of a finished slice made without analysis (the overlay
 *  was off): the figures of the whole part and the masks of the overlay. */
export async function analyseVoids(page: Page, s: Slice): Promise<void> {
  const { store, pool } = page;
  if (store.busy || store.slice !== s || !s.complete || s.source !== "stl" || s.analysed >= s.layers) return;
  const gen = ++store.generation;
  store.busy = true;
  setState("slicing");
  const label = "Analysing voids…";
  progress(0, label);
  updateButtons(page);
  // every layer is analysed again: what an earlier, cancelled pass analysed is dropped
  s.figures.restartAnalysis();
  let arrived = 0;
  // the bar and the figures in one throttled redraw, whichever asked for it
  const redraw = () => {
    progress(arrived / Math.max(1, s.layers), label);
    writeStats(page);
  };
  const figuresChanged = () => {
    if (store.slice === s && gen === store.generation) whileBusy(page, gen, redraw);
  };
  try {
    await pool.analyse(
      s.layers,
      (l) => {
        if (gen !== store.generation) return;
        s.put(l, store.current);
        arrived++;
        if (l.index === store.current) show(page, store.current);
        whileBusy(page, gen, redraw);
      },
      (u) => {
        if (gen !== store.generation) return;
        s.addUnit(u);
        s.figures.refresh(pool, figuresChanged).catch(() => {});
      },
    );
    if (gen !== store.generation) return;
    await s.figures.refresh(pool, figuresChanged);
    if (gen !== store.generation) return;
    store.busy = false;
    progress(null);
    show(page, store.current);
    setState("done");
  } catch (e) {
    failed(page, gen, e);
  } finally {
    if (gen === store.generation) updateButtons(page);
  }
}

/** Ends a slice or a G-code read that threw: cancelled, or an error shown in the page. */
function failed(page: Page, gen: number, e: unknown): void {
  if (gen !== page.store.generation) return;
  page.store.busy = false;
  progress(null);
  if (e instanceof Cancelled) setState("cancelled");
  else showError(page, e);
}

export async function openGcode(page: Page, file: File): Promise<void> {
  const { store, pool, renderer } = page;
  cancelRunning(page);
  hideBanner();
  const gen = ++store.generation;
  const s = store.newSlice("gco", file.name, NaN, NaN, page.form!.values(), null);
  store.busy = true;
  setState("slicing");
  progress(0, "Reading G-code…");
  updateButtons(page);
  let read = 0;
  try {
    const r: GcodeParseResult = await pool.parseGcode(file, (l) => {
      if (gen !== store.generation) return;
      s.put(l, 0);
      read++;
      progress(l.fraction ?? 0, `Reading ${file.name}… ${read} layers`);
    });
    if (gen !== store.generation) return;
    s.open(r.layers, {});
    s.dropletWidth = r.dropletWidth;
    s.layerHeight = r.layerHeight;
    s.gcodeFile = { file, header: r.header, settings: r.settings, settingsError: r.settingsError };
    s.figures.setRead(r.figures, r.figuresError, r.figuresNote);
    // the form shows the file's settings (views/controls.ts says so, or how it differs)
    if (r.settings) page.form!.setRaw(r.settings);
    s.complete = true;
    store.slice = s;
    const before = store.job;
    store.job = null;
    // the job it replaced is one Undo away
    record(page, `open ${file.name}`, "open");
    if (before?.parts.length) undoNotice(page, `“${file.name}” replaced the job.`);
    page.parts.render();
    setLayers(r.layers);
    showModel(file.name);
    store.busy = false;
    progress(null);
    store.viewTouched = false;
    renderer.fit(s.bbox);
    show(page, Math.floor((r.layers - 1) * 0.3));
    setState("done");
  } catch (e) {
    failed(page, gen, e);
  } finally {
    if (gen === store.generation) updateButtons(page);
  }
}

/** The slice is dropped (it broke, was cancelled, or belongs to a job no longer shown):
 *  nothing of it is shown, downloaded or linked. */
export function dropSlice(page: Page): void {
  const { store, renderer } = page;
  store.slice = null;
  renderer.current = renderer.below = null;
  renderer.request();
  page.view3d.sync(page);
  writeStats(page);
  layerLabel(page);
}

/** Cancel: the workers stop at once; a slice not yet complete is dropped. */
export function cancel(page: Page): void {
  const { store, pool } = page;
  if (!store.busy) return;
  store.generation++;
  pool.cancel();
  store.busy = false;
  progress(null);
  setState("cancelled");
  showBanner("Slicing cancelled.", "Change the settings or open another file, then slice again.", "info");
  if (store.slice && !store.slice.complete) dropSlice(page);
  restoreModel(page);
  updateButtons(page);
}

/** The unit fix: x, y and z of the parts whose file suggests `factor` (all parts when none
 *  does) scaled by it, and the job sliced again. */
export function fixUnits(page: Page, factor: number): void {
  const job = page.store.job;
  if (!job) return;
  const suggests = job.parts.filter((p) => job.models.get(p.spec.file)?.info.suggested_scale === factor);
  const which = suggests.length ? suggests : job.parts;
  // busy from the click on (the layout comes first, then the slice)
  setState("reading");
  void editParts(page, which.map((p) => ({ id: p.id, changes: { scale_x: p.spec.scale_x * factor, scale_y: p.spec.scale_y * factor, scale_z: p.spec.scale_z * factor } })), `scale ×${factor}`)
    .then((ok) => {
      if (ok) void startSlice(page);
      else setState("error");
    });
}

/** The G-code of the finished slice: the core's header and footer around the layers' pieces. */
export async function download(page: Page): Promise<void> {
  const { store, pool } = page;
  const s = store.slice;
  // only the slice of the job as it is now (the button says so when it is not)
  if (!s || !s.complete || s.source !== "stl" || sliceState(page) !== "current" || jobOffPlate(store.job, page.form?.values()).length) return;
  const summary = s.figures.summary;
  try {
    if (!summary) throw new SliceError("internal", "the slice has no summary from the core");
    const [header, footer] = await Promise.all([pool.header(summary), pool.footer(summary)]);
    const layers = s.gcodeParts();
    if (typeof layers === "number") throw new SliceError("internal", `layer ${layers + 1} has no G-code`);
    saveGcode(new Blob([header, ...layers, footer], { type: "text/plain" }), s.job?.refs[0]?.name ?? s.name, (s.job?.refs.length ?? 1) - 1);
  } catch (e) {
    showError(page, e);
  }
}

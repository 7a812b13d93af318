// Page wiring only: events -> worker pool -> layer store -> renderer and statistics.

import { Cancelled, MAX_WORKERS, Pool, SliceError } from "./client";
import { SettingsForm, type Value } from "./form";
import { addNumbers, type Counts, type GcodeParseResult, type InitResult, type JobInfo, type LayerAnalysis, type LayerData, type SliceUnit } from "./protocol";
import { Renderer, type Bounds, type View } from "./render";
import { sampleStl } from "./sample";
import { LinkError, makeLink, readLink, sha256Hex, type SharedLink } from "./share";

const $ = <T extends HTMLElement = HTMLElement>(id: string) => document.getElementById(id) as T;

/** Tuning through the query string (used by the tests): `?workers=3&cache=2` (MB). */
const query = new URLSearchParams(location.search);

/** Layer previews kept in the page; beyond this, layers far from the one shown are dropped
 *  and re-planned by a worker when they are shown again. */
const CACHE_BUDGET_BYTES = Math.min(4096, Math.max(1, Number(query.get("cache")) || 384)) * 2 ** 20;

interface Model {
  bytes: Uint8Array;
  name: string;
  sha256: string;
}

/** Everything known about one slice (or one opened .gco file). */
class Slice {
  layers = 0;
  info: JobInfo = {};
  z: number[] = [];
  counts: (Counts | undefined)[] = [];
  travelMm: number[] = [];
  /** G-code by runs of layers, keyed by the run's first layer. */
  gcode = new Map<number, { to: number; blob: Blob }>();
  cache = new Map<number, LayerData>();
  cacheBytes = 0;
  done = 0;
  complete = false;
  bbox: Bounds = { minX: Infinity, minY: Infinity, maxX: -Infinity, maxY: -Infinity };
  totals: Counts = { outer: 0, inner: 0, fill: 0 };
  travelTotal = 0;
  /** What slicing repaired (from the core, once the slice is complete). */
  repairs: string[] = [];
  /** Sum of the layers' summaries (the core's Summary, for the header and footer). */
  summary: Record<string, unknown> = {};
  /** Void analysis per layer (when the slice or a later pass made it). */
  analysis: (LayerAnalysis | undefined)[] = [];
  analysed = 0;
  regionArea = 0;
  coveredArea = 0;
  /** When the file was chosen (performance.now()), and the seconds from then until every
   *  layer's G-code was ready (the figure of the benchmark). */
  startedAt = performance.now();
  seconds: number | null = null;
  /** The worst layer: the one with the largest connected void. */
  worst: { index: number; area: number } | null = null;

  constructor(
    readonly source: "stl" | "gco",
    readonly name: string,
    public dropletWidth: number,
    public layerHeight: number,
    readonly settings: Record<string, Value>,
    readonly model: Model | null,
  ) {}

  open(layers: number, info: JobInfo): void {
    this.layers = layers;
    this.info = info;
  }

  put(l: LayerData, current: number): void {
    if (this.counts[l.index] === undefined) {
      this.done++;
      this.counts[l.index] = l.counts;
      this.z[l.index] = l.z;
      this.travelMm[l.index] = l.travelMm;
      this.totals.outer += l.counts.outer;
      this.totals.inner += l.counts.inner;
      this.totals.fill += l.counts.fill;
      this.travelTotal += l.travelMm;
      const d = l.droplets;
      const b = this.bbox;
      for (let i = 0; i < d.length; i += 2) {
        const x = d[i];
        const y = d[i + 1];
        if (x < b.minX) b.minX = x;
        if (x > b.maxX) b.maxX = x;
        if (y < b.minY) b.minY = y;
        if (y > b.maxY) b.maxY = y;
      }
    }
    const a = l.analysis;
    if (a && this.analysis[l.index] === undefined) {
      this.analysis[l.index] = a;
      this.analysed++;
      this.regionArea += a.region_area;
      this.coveredArea += a.covered_area;
      const v = a.largest_void;
      if (v && (!this.worst || v.area > this.worst.area)) this.worst = { index: l.index, area: v.area };
    }
    const old = this.cache.get(l.index);
    if (!old || (l.mask && !old.mask)) {
      if (old) this.cacheBytes -= layerBytes(old);
      this.cache.set(l.index, l);
      this.cacheBytes += layerBytes(l);
    }
    if (this.source === "stl") this.evict(current);
  }

  /** A run of layers is complete: its G-code and its part of the summary. */
  addUnit(u: SliceUnit): void {
    if (u.gcode) this.gcode.set(u.from, { to: u.to, blob: u.gcode });
    if (u.summary) addNumbers(this.summary, u.summary);
  }

  /** The G-code of every layer in order, or the first layer without any. */
  gcodeParts(): Blob[] | number {
    const parts: Blob[] = [];
    for (let i = 0; i < this.layers; ) {
      const u = this.gcode.get(i);
      if (!u) return i;
      parts.push(u.blob);
      i = u.to;
    }
    return parts;
  }

  private evict(current: number): void {
    if (this.cacheBytes <= CACHE_BUDGET_BYTES) return;
    const far = [...this.cache.keys()].sort((a, b) => Math.abs(b - current) - Math.abs(a - current));
    for (const i of far) {
      if (this.cacheBytes <= CACHE_BUDGET_BYTES * 0.8 || Math.abs(i - current) <= 1) break;
      const l = this.cache.get(i)!;
      this.cacheBytes -= layerBytes(l);
      this.cache.delete(i);
    }
  }

  get droplets(): number {
    return this.totals.outer + this.totals.inner + this.totals.fill;
  }
}

/** Bytes a cached layer holds (droplets, roles, travel and the void mask's tiles). */
function layerBytes(l: LayerData): number {
  let m = 0;
  for (const t of l.mask?.tiles ?? []) m += t.void.byteLength + t.overfill.byteLength;
  return l.droplets.byteLength + l.roles.byteLength + l.travel.byteLength + m;
}

// ---------------------------------------------------------------------------------------------
// state

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
const pool = asked === null ? new Pool() : new Pool(asked);
const renderer = new Renderer($<HTMLCanvasElement>("view"));
let form: SettingsForm;
let init: InitResult;
let model: Model | null = null;
let slice: Slice | null = null;
let current = 0;
let generation = 0;
let busy = false;
let viewTouched = false;
let pendingLink: SharedLink | null = null;
let slicedSettings = "";
const previewRequests = new Set<number>();

const slider = $<HTMLInputElement>("layer");

function setState(state: "loading" | "reading" | "idle" | "slicing" | "done" | "error" | "cancelled"): void {
  document.body.dataset.state = state;
}

// ---------------------------------------------------------------------------------------------
// messages

const TITLES: Record<string, string> = {
  import: "",
  setting: "Bad setting.",
  nothing_to_print: "Nothing to print.",
  crash: "The slicer crashed.",
  internal: "Internal error.",
  link: "Cannot open this preview link.",
  linkPart: "Parts of this preview link were ignored.",
};

function showBanner(title: string, message: string, tone: "error" | "info" | "ok" = "error"): void {
  const b = $("banner");
  b.className = `banner ${tone === "error" ? "" : tone}`;
  $("banner-title").textContent = title;
  $("banner-title").hidden = title === "";
  $("banner-message").textContent = message;
  b.hidden = false;
  b.dataset.kind = tone;
}

function hideBanner(): void {
  $("banner").hidden = true;
}

/** After the workers were replaced (cancel, crash), lets them hold the finished slice's model
 *  again, so its evicted layers and its download keep working. */
function restoreModel(): void {
  const s = slice;
  if (!s || !s.complete || s.source !== "stl" || !s.model || busy) return;
  pool.open(s.model.bytes, s.model.name, JSON.stringify(s.settings)).catch(() => {
    // the slice stays visible; what needs a worker reports its own error
  });
}

function showError(e: unknown): void {
  if (e instanceof SliceError && e.kind === "crash") restoreModel();
  if (e instanceof SliceError) {
    showBanner(TITLES[e.kind] ?? "Error.", capitalize(e.message));
  } else if (e instanceof Error) {
    showBanner("Something went wrong.", e.message);
  } else {
    showBanner("Something went wrong.", String(e));
  }
  setState("error");
}

function capitalize(s: string): string {
  return s.charAt(0).toUpperCase() + s.slice(1);
}

function note(text: string, tone: "warn" | "ok" | "none"): void {
  const n = $("link-note");
  n.hidden = tone === "none";
  n.textContent = text;
  n.className = tone === "ok" ? "banner ok" : "note";
}

// ---------------------------------------------------------------------------------------------
// progress

function progress(fraction: number | null, label = "Slicing…"): void {
  const p = $("progress");
  if (fraction === null) {
    p.hidden = true;
    return;
  }
  p.hidden = false;
  const pct = Math.floor(fraction * 100);
  $("progress-label").textContent = label;
  $("progress-pct").textContent = `${pct} %`;
  $("progress-fill").style.transform = `scaleX(${pct / 100})`;
  p.dataset.percent = String(pct);
}

// ---------------------------------------------------------------------------------------------
// statistics

const nf = new Intl.NumberFormat("en-US");
const fmtMm = (x: number) => `${x.toFixed(1)}`;

function duration(seconds: number): string {
  if (!Number.isFinite(seconds)) return "–";
  const h = Math.floor(seconds / 3600);
  const m = Math.floor((seconds % 3600) / 60);
  const s = Math.round(seconds % 60);
  if (h > 0) return `${h} h ${m} min`;
  if (m > 0) return `${m} min ${s} s`;
  return `${s} s`;
}

function num(name: string, fallback: number): number {
  const v = slice?.settings[name] ?? form?.get(name);
  return typeof v === "number" ? v : fallback;
}

/** While the workers run, the progress and the figures are redrawn at most this often: each
 *  redraw costs style, layout and paint, and with few cores that time is taken from slicing. */
const BUSY_REDRAW_MS = 150;
let busyRedraw: { gen: number; update: () => void } | null = null;

/** Runs `update` within [[BUSY_REDRAW_MS]], once for all calls until then, unless the run `gen`
 *  has ended by then (the page is then drawn by whatever ended it). */
function whileBusy(gen: number, update: () => void): void {
  const pending = busyRedraw !== null;
  busyRedraw = { gen, update };
  if (pending) return;
  setTimeout(() => {
    const r = busyRedraw;
    busyRedraw = null;
    if (r && r.gen === generation && busy) r.update();
  }, BUSY_REDRAW_MS);
}

function roleLabels(source: "stl" | "gco"): void {
  const gco = source === "gco";
  $("legend-0").textContent = $("stat-label-0").textContent = gco ? "Loop droplets (G26)" : "Outer loop";
  $("legend-2").textContent = $("stat-label-2").textContent = gco ? "Fill lines (G25)" : "Fill";
  $("legend-1-wrap").hidden = gco;
}

/** Sets an element's text; an unchanged text is left alone (no layout for nothing). */
function setText(id: string, text: string): void {
  const e = $(id);
  if (e.textContent !== text) e.textContent = text;
}

function writeStats(): void {
  const s = slice;
  roleLabels(s?.source ?? "stl");
  $("empty").hidden = s !== null;
  if (!s) {
    writeVoids(null);
    for (const id of ["stat-model", "stat-size", "stat-facets", "stat-layers", "stat-droplet", "stat-outer", "stat-inner", "stat-fill", "stat-droplets", "stat-volume", "stat-mass", "stat-time", "stat-travel", "stat-z", "stat-layer-droplets"]) setText(id, "–");
    $("warnings").hidden = true;
    return;
  }
  setText("stat-model", s.name);
  const b = s.info.bounds;
  if (b) setText("stat-size", `${fmtMm(b.max[0] - b.min[0])} × ${fmtMm(b.max[1] - b.min[1])} × ${fmtMm(b.max[2] - b.min[2])} mm`);
  else if (Number.isFinite(s.bbox.minX)) setText("stat-size", `${fmtMm(s.bbox.maxX - s.bbox.minX)} × ${fmtMm(s.bbox.maxY - s.bbox.minY)} mm (droplets)`);
  else setText("stat-size", "–");
  const facets = s.info.mesh?.facets_in_file;
  setText("stat-facets", facets !== undefined ? nf.format(facets) : s.source === "gco" ? "(G-code file)" : "–");
  setText("stat-layers", s.complete || s.done === s.layers ? nf.format(s.layers) : `${nf.format(s.done)} of ${nf.format(s.layers)}`);
  setText("stat-droplet", `${s.dropletWidth.toFixed(3)} × ${s.layerHeight.toFixed(3)} mm`);
  setText("stat-outer", nf.format(s.totals.outer));
  setText("stat-inner", nf.format(s.totals.inner));
  setText("stat-fill", nf.format(s.totals.fill));
  setText("stat-droplets", nf.format(s.droplets));
  const volume = s.droplets * s.dropletWidth * s.dropletWidth * s.layerHeight; // mm³
  setText("stat-volume", `${(volume / 1000).toFixed(2)} cm³`);
  setText("stat-mass", `${((volume / 1000) * num("material_density", 1.04)).toFixed(2)} g`);
  const seconds = s.droplets / num("droplet_rate", 100) + s.travelTotal / num("travel_speed", 50);
  setText("stat-time", (s.complete ? "" : "≥ ") + duration(seconds));
  setText("stat-travel", `${(s.travelTotal / 1000).toFixed(2)} m`);
  const c = s.counts[current];
  setText("stat-z", s.z[current] !== undefined ? `${s.z[current].toFixed(3)} mm` : "–");
  setText("stat-layer-droplets", c ? nf.format(c.outer + c.inner + c.fill) : "–");
  writeVoids(s);
  const warnings = [...((s.info.warnings ?? []) as string[]), ...s.repairs];
  $("warnings").hidden = warnings.length === 0;
  const list = $("warning-list");
  const text = warnings.join("\n");
  if (list.dataset.text !== text) {
    // rebuilt only when it changes: writeStats runs many times during a slice
    list.dataset.text = text;
    list.replaceChildren(
      ...warnings.map((w) => {
        const li = document.createElement("li");
        li.textContent = w;
        return li;
      }),
    );
  }
  writeUnitFix(s);
}

/**
 * The unit rule's fix, offered, never applied silently: when the part's size suggests the file
 * is in inches (or micrometres), a button scales x, y and z by the suggested factor and slices
 * again.
 */
function writeUnitFix(s: Slice): void {
  const factor = s.info.suggested_scale;
  const btn = $("btn-unit-fix") as HTMLButtonElement;
  btn.hidden = typeof factor !== "number" || s.model === null;
  if (typeof factor !== "number" || btn.hidden) return;
  btn.textContent = factor > 1 ? `Scale ×${factor} (inches → mm)` : `Scale ×${factor} (µm → mm)`;
  btn.title = "Scale x, y and z by this factor and slice again";
  btn.onclick = () => {
    const scaled: Record<string, Value> = {};
    for (const axis of ["scale_x", "scale_y", "scale_z"]) scaled[axis] = Number(form.get(axis) ?? 1) * factor;
    form.set(scaled);
    if (s.model) void startSlice(s.model);
  };
}

const pct = (x: number) => `${(x * 100).toFixed(1)} %`;
const mm2 = (x: number) => `${x < 0.1 ? x.toFixed(3) : x.toFixed(2)} mm²`;

/** The "Voids" block of the statistics: this layer, the part, the worst layer. */
function writeVoids(s: Slice | null): void {
  const a = s?.analysis[current];
  setText("stat-coverage", a ? pct(a.coverage) : "–");
  setText("stat-void", a ? mm2(a.void_area) : "–");
  const v = a?.largest_void;
  setText("stat-largest", v ? `${mm2(v.area)}${v.at_boundary ? " (edge)" : ""}` : a ? "none" : "–");
  const partial = s && s.analysed < s.layers ? " so far" : "";
  setText("stat-part-coverage", s && s.analysed > 0 && s.regionArea > 0 ? pct(s.coveredArea / s.regionArea) + partial : "–");
  setText("stat-worst", s?.worst ? `${nf.format(s.worst.index + 1)} · ${mm2(s.worst.area)}` : "–");
  ($("btn-worst") as HTMLButtonElement).disabled = !s?.worst;
  const hint = $("voids-hint");
  if (s?.source === "gco") hint.textContent = "Voids are analysed for sliced STL files.";
  else if (!s || s.analysed === 0) hint.replaceChildren("Turn on ", Object.assign(document.createElement("b"), { textContent: "Voids" }), " to analyse.");
  else if (s.analysed < s.layers) hint.textContent = `Analysed ${nf.format(s.analysed)} of ${nf.format(s.layers)} layers.`;
  else hint.textContent = "Worst: largest connected void.";
}

// ---------------------------------------------------------------------------------------------
// layers

function layerLabel(): void {
  const s = slice;
  const out = $("layer-label");
  if (!s || s.layers === 0) {
    out.textContent = "–";
    return;
  }
  const z = s.z[current];
  out.textContent = `Layer ${current + 1} / ${s.layers}` + (z !== undefined ? ` · z ${z.toFixed(2)} mm` : "");
}

function show(i: number): void {
  const s = slice;
  if (!s || s.layers === 0) return;
  current = clampLayer(Number.isFinite(i) ? i : current, s.layers);
  slider.value = String(current);
  layerLabel();
  renderer.current = s.cache.get(current) ?? null;
  renderer.below = current > 0 ? (s.cache.get(current - 1) ?? null) : null;
  renderer.dropletWidth = s.dropletWidth;
  renderer.request();
  writeStats();
  for (const k of [current, current - 1]) {
    if (k >= 0 && !s.cache.has(k) && s.complete && s.source === "stl") fetchPreview(s, k);
  }
  // the overlay needs the current layer's mask (evicted, or sliced without analysis)
  const shown = s.cache.get(current);
  if (renderer.showVoids && shown && !shown.mask && s.complete && s.source === "stl") fetchPreview(s, current);
}

/** A layer index within [0, layers): rounded, clamped; 0 when it is not a number. */
function clampLayer(i: number, layers: number): number {
  if (!Number.isFinite(i)) return 0;
  return Math.max(0, Math.min(layers - 1, Math.round(i)));
}

function fetchPreview(s: Slice, k: number): void {
  if (previewRequests.has(k)) return;
  previewRequests.add(k);
  (renderer.showVoids ? pool.previewAnalysed(k) : pool.preview(k))
    .then((l) => {
      if (slice !== s) return;
      s.put(l, current);
      if (k === current || k === current - 1) show(current);
    })
    .catch((e) => {
      if (!(e instanceof Cancelled)) showError(e);
    })
    .finally(() => previewRequests.delete(k));
}

// ---------------------------------------------------------------------------------------------
// slicing

interface Target {
  layer?: number;
  view?: View;
  /** Shown once the slice has started (a slice hides the banner): about the link that asked
   *  for it. */
  notice?: { title: string; message: string; tone?: "error" | "info" };
}

function settingsProblem(): boolean {
  const errors = form.errors();
  if (errors.length === 0) return false;
  showBanner(TITLES.setting, `Fix ${errors.map((e) => `${e.name.replace(/_/g, " ")} (${e.message})`).join(", ")} before slicing.`);
  form.focusFirstError();
  setState("error");
  return true;
}

function cancelRunning(): void {
  if (busy) {
    pool.cancel();
    busy = false;
  }
}

async function startSlice(m: Model, target: Target = {}): Promise<void> {
  if (settingsProblem()) return;
  cancelRunning();
  hideBanner();
  if (target.notice) showBanner(target.notice.title, target.notice.message, target.notice.tone);
  const gen = ++generation;
  const values = form.values();
  const json = form.json();
  const H = Number(values.layer_height);
  const B = H * Number(values.droplet_aspect);
  const s = new Slice("stl", m.name, B, H, values, m);
  if (fileChosenAt !== null) s.startedAt = fileChosenAt;
  fileChosenAt = null;
  const sameModel = slice?.model?.sha256 === m.sha256;
  busy = true;
  setState("slicing");
  progress(0, `Reading ${m.name}…`);
  updateButtons();
  try {
    await pool.slice(m.bytes, m.name, json, {
      opened: (r) => {
        if (gen !== generation) return;
        s.open(r.layers, r.info);
        model = m;
        slice = s;
        slicedSettings = json;
        slider.max = String(Math.max(0, r.layers - 1));
        progress(0);
        $("model-name").textContent = m.name;
        $("empty").hidden = true;
        const wanted = target.layer ?? (sameModel ? current : Math.floor((r.layers - 1) * 0.3));
        current = clampLayer(wanted, r.layers);
        if (target.view) {
          // the renderer keeps any view within its limits
          renderer.view = { ...target.view };
          viewTouched = true;
        } else if (!sameModel || !viewTouched) {
          viewTouched = false;
          const b = r.info.bounds;
          renderer.fit(b ? { minX: b.min[0], minY: b.min[1], maxX: b.max[0], maxY: b.max[1] } : null);
        }
        show(current);
      },
      layer: (l) => {
        if (gen !== generation) return;
        s.put(l, current);
        // the layer shown and the one below it: drawn once both have arrived (a draw costs)
        const arrived = (k: number) => k < 0 || s.counts[k] !== undefined;
        if ((l.index === current || l.index === current - 1) && arrived(current) && arrived(current - 1)) show(current);
        // the last layer shows 100 % at once; before it the figures are redrawn now and then
        if (s.done === s.layers) progress(1);
        else {
          whileBusy(gen, () => {
            progress(s.done / Math.max(1, s.layers));
            writeStats();
          });
        }
      },
      unit: (u) => {
        if (gen === generation) s.addUnit(u);
      },
    }, renderer.showVoids);
    if (gen !== generation) return;
    s.complete = true;
    s.seconds = (performance.now() - s.startedAt) / 1000;
    busy = false;
    progress(null);
    if (!viewTouched && !s.info.bounds) renderer.fit(s.bbox);
    show(current);
    setState("done");
    if (s.droplets === 0) {
      showBanner(
        "Nothing to print",
        `No droplet fits in this part: every wall is thinner than the droplet width B = ${s.dropletWidth.toFixed(3)} mm. ` +
          "Scale the part up (Part → scale) or use smaller droplets (layer height, droplet aspect).",
      );
    }
    // the overlay was turned on during a slice made without analysis
    if (renderer.showVoids && s.analysed < s.layers) void analyseVoids(s);
    pool
      .repairs(JSON.stringify({ ...s.summary, layers: s.layers }))
      .then((r) => {
        s.repairs = r;
        if (slice === s) writeStats();
      })
      .catch(() => {
        // only informative; a failure here must not disturb the finished slice
      });
  } catch (e) {
    if (gen !== generation) return;
    busy = false;
    progress(null);
    if (e instanceof Cancelled) {
      setState("cancelled");
      showBanner("Slicing cancelled.", "Change the settings or open another file, then slice again.", "info");
    } else {
      if (slice === s) {
        // the slice broke half-way: nothing of it can be downloaded
        slice = null;
        renderer.current = renderer.below = null;
        renderer.request();
        writeStats();
      }
      showError(e);
    }
  } finally {
    if (gen === generation) updateButtons();
  }
}

/** Re-plans and analyses every layer of a finished slice made without analysis (the overlay
 *  was off): the figures of the whole part and the masks of the overlay. */
async function analyseVoids(s: Slice): Promise<void> {
  if (busy || slice !== s || !s.complete || s.source !== "stl" || s.analysed >= s.layers) return;
  const gen = ++generation;
  busy = true;
  setState("slicing");
  const label = "Analysing voids…";
  progress(s.analysed / Math.max(1, s.layers), label);
  updateButtons();
  try {
    await pool.analyse(s.layers, (l) => {
      if (gen !== generation) return;
      s.put(l, current);
      if (l.index === current) show(current);
      whileBusy(gen, () => {
        progress(s.analysed / Math.max(1, s.layers), label);
        writeStats();
      });
    });
    if (gen !== generation) return;
    busy = false;
    progress(null);
    show(current);
    setState("done");
  } catch (e) {
    failed(gen, e);
  } finally {
    if (gen === generation) updateButtons();
  }
}

/** Ends a slice or a G-code read that threw: cancelled, or an error shown in the page. */
function failed(gen: number, e: unknown): void {
  if (gen !== generation) return;
  busy = false;
  progress(null);
  if (e instanceof Cancelled) setState("cancelled");
  else showError(e);
}

async function openGcode(file: File): Promise<void> {
  cancelRunning();
  hideBanner();
  const gen = ++generation;
  const s = new Slice("gco", file.name, NaN, NaN, form.values(), null);
  busy = true;
  setState("slicing");
  progress(0, "Reading G-code…");
  updateButtons();
  let read = 0;
  try {
    const r: GcodeParseResult = await pool.parseGcode(file, (l) => {
      if (gen !== generation) return;
      s.put(l, 0);
      read++;
      progress(l.fraction ?? 0, `Reading ${file.name}… ${read} layers`);
    });
    if (gen !== generation) return;
    s.open(r.layers, {});
    s.dropletWidth = r.dropletWidth;
    s.layerHeight = r.layerHeight;
    s.complete = true;
    slice = s;
    model = null;
    slider.max = String(Math.max(0, r.layers - 1));
    $("model-name").textContent = file.name;
    $("empty").hidden = true;
    busy = false;
    progress(null);
    viewTouched = false;
    renderer.fit(s.bbox);
    show(Math.floor((r.layers - 1) * 0.3));
    setState("done");
  } catch (e) {
    failed(gen, e);
  } finally {
    if (gen === generation) updateButtons();
  }
}

function updateButtons(): void {
  const s = slice;
  const ready = !busy && s !== null && s.complete;
  // Like the CLI, no code for a part without a single droplet.
  ($("btn-download") as HTMLButtonElement).disabled = !(ready && s!.source === "stl" && s!.droplets > 0);
  ($("btn-share") as HTMLButtonElement).disabled = !(ready && s!.source === "stl" && model !== null);
  ($("btn-slice") as HTMLButtonElement).disabled = model === null || form === undefined;
  settingsStatus();
}

function settingsStatus(): void {
  if (!form) return;
  const st = $("settings-status");
  const errors = form.errors();
  const btn = $("btn-slice");
  if (errors.length) {
    st.textContent = `${errors.length} setting${errors.length > 1 ? "s are" : " is"} invalid.`;
    st.className = "hint bad";
    ($("btn-slice") as HTMLButtonElement).disabled = true;
    btn.classList.remove("attention");
    return;
  }
  const stale = model !== null && slice?.source === "stl" && form.json() !== slicedSettings;
  st.className = "hint";
  st.textContent = stale ? "Settings changed: press Slice (or Enter) to update." : "";
  btn.classList.toggle("attention", stale);
}

// ---------------------------------------------------------------------------------------------
// files

/** When the file being opened was chosen: a slice's time runs from there. */
let fileChosenAt: number | null = null;

async function openFile(file: File): Promise<void> {
  const chosen = performance.now();
  setState("reading");
  if (/\.(gco|gcode)$/i.test(file.name)) {
    pendingLink = null;
    note("", "none");
    await openGcode(file);
    return;
  }
  let bytes: Uint8Array;
  try {
    bytes = new Uint8Array(await file.arrayBuffer());
  } catch (e) {
    showBanner(TITLES.import, `The browser could not read “${file.name}”: ${String(e)}`);
    return;
  }
  const m: Model = { bytes, name: file.name, sha256: await sha256Hex(bytes) };
  fileChosenAt = chosen;
  const link = pendingLink;
  if (link) {
    pendingLink = null;
    if (link.state.sha256 === m.sha256) {
      note(`“${m.name}” matches the model of the preview link.`, "ok");
      await startSlice(m, { layer: link.state.layer, view: link.state.view });
      return;
    }
    note(
      `“${m.name}” does not match the model of the preview link (“${link.state.name}”, SHA-256 ${link.state.sha256.slice(0, 12)}…): this is a different file. It is sliced with the link's settings.`,
      "warn",
    );
  } else {
    note("", "none");
  }
  await startSlice(m);
}

function sample(): Model {
  const s = sampleStl();
  return { bytes: s.bytes, name: s.name, sha256: "" };
}

async function openSample(notice?: Target["notice"]): Promise<void> {
  const m = sample();
  m.sha256 = await sha256Hex(m.bytes);
  pendingLink = null;
  note("", "none");
  await startSlice(m, { notice });
}

// ---------------------------------------------------------------------------------------------
// download and links

function baseName(name: string): string {
  return name.replace(/\.[^.]*$/, "") || "model";
}

async function download(): Promise<void> {
  const s = slice;
  if (!s || !s.complete || s.source !== "stl") return;
  const summary = JSON.stringify({ ...s.summary, layers: s.layers });
  try {
    const [header, footer] = await Promise.all([pool.header(summary), pool.footer(summary)]);
    const layers = s.gcodeParts();
    if (typeof layers === "number") throw new SliceError("internal", `layer ${layers + 1} has no G-code`);
    const blob = new Blob([header, ...layers, footer], { type: "text/plain" });
    const a = document.createElement("a");
    a.href = URL.createObjectURL(blob);
    a.download = `${baseName(s.name)}.gco`;
    document.body.append(a);
    a.click();
    a.remove();
    setTimeout(() => URL.revokeObjectURL(a.href), 60_000);
  } catch (e) {
    showError(e);
  }
}

async function share(): Promise<void> {
  const s = slice;
  if (!s || !model || s.source !== "stl") return;
  const { url, embedded } = await makeLink(location.href, {
    settings: changedFrom(s.settings),
    layer: current,
    view: { ...renderer.view },
    name: model.name,
    sha256: model.sha256,
    showTravel: renderer.showTravel,
  }, model.bytes);
  let copied = false;
  try {
    // some browsers never settle the promise when they do not grant the permission
    copied = await Promise.race([
      navigator.clipboard.writeText(url).then(() => true),
      new Promise<boolean>((ok) => setTimeout(() => ok(false), 1500)),
    ]);
  } catch {
    // clipboard refused (permissions, insecure context): the dialog shows the link to copy
  }
  $("share-text").textContent =
    (copied ? "Copied to the clipboard. " : "Copy this link. ") +
    (embedded
      ? `The model is inside the link (${Math.round(url.length / 1024)} KB), so it opens the same slice anywhere.`
      : `“${model.name}” is too big to embed, so the link carries its SHA-256: whoever opens it drops in the same file and the page checks that it matches.`);
  const input = $<HTMLInputElement>("share-url");
  input.value = url;
  $<HTMLDialogElement>("share-dialog").showModal();
  input.select();
}

function changedFrom(values: Record<string, Value>): Record<string, Value> {
  const out: Record<string, Value> = {};
  for (const [k, v] of Object.entries(values)) if (init.defaults[k] !== v) out[k] = v;
  return out;
}

/** What a link's settings must be for each kind of setting (the form checks the ranges). */
const KIND_TYPE: Record<string, { type: string; words: string }> = {
  number: { type: "number", words: "a number" },
  integer: { type: "number", words: "a whole number" },
  bool: { type: "boolean", words: "yes or no (true/false)" },
  enum: { type: "string", words: "one of the choices" },
};

/** The link's settings whose type fits their kind; the others named in `ignored`. Unknown
 *  names are kept (the form ignores them and the page says so). */
function linkSettings(settings: Record<string, Value>, ignored: string[]): Record<string, Value> {
  const out: Record<string, Value> = {};
  for (const [name, v] of Object.entries(settings)) {
    const spec = init.schema.find((x) => x.name === name);
    const want = spec ? KIND_TYPE[spec.kind] : undefined;
    if (want && typeof v !== want.type) {
      const shown = typeof v === "string" ? JSON.stringify(v.length > 24 ? `${v.slice(0, 24)}…` : v) : String(v);
      ignored.push(`its setting ${name} (${shown} is not ${want.words}: the default is used)`);
      continue;
    }
    out[name] = v;
  }
  return out;
}

/** Opens the preview link in the URL, if there is one (returns whether there was one that the
 *  page now shows or waits for a file of). A link too large or damaged is refused with a
 *  message and the sample part is shown; fields it gets wrong are ignored and named. */
async function openLink(): Promise<boolean> {
  let link: SharedLink | null;
  try {
    link = await readLink(location.hash);
  } catch (e) {
    const why = e instanceof LinkError ? e.message : `it could not be read (${e instanceof Error ? e.message : String(e)})`;
    await openSample({ title: TITLES.link, message: `This preview link is too large or damaged: ${why}. Showing the sample part instead.` });
    return true;
  }
  if (!link) return false;
  const ignored = [...link.ignored];
  const unknown = form.set({ ...init.defaults, ...linkSettings(link.state.settings, ignored) });
  const extra = unknown.length
    ? ` The link comes from another version: its settings ${unknown.join(", ")} are unknown here and were ignored, so the slice may differ.`
    : "";
  if (extra) note(extra.trim(), "warn");
  renderer.showTravel = Boolean(link.state.showTravel);
  $<HTMLInputElement>("opt-travel").checked = renderer.showTravel;
  $("legend-travel").hidden = !renderer.showTravel;
  const notice: Target["notice"] = ignored.length
    ? { title: TITLES.linkPart, message: `This preview link is partly damaged: ${ignored.join("; ")}.`, tone: "info" }
    : undefined;
  const { layer, view, name, sha256 } = link.state;
  if (link.model) {
    const m: Model = { bytes: link.model, name, sha256: await sha256Hex(link.model) };
    if (m.sha256 === sha256) {
      await startSlice(m, { layer, view, notice });
      return true;
    }
    link.model = null;
    link.modelError = "its model does not match the SHA-256 it carries";
  }
  pendingLink = link;
  $("empty").hidden = false;
  const at = layer !== undefined ? ` to see layer ${nf.format(layer + 1)}` : "";
  if (link.modelError) {
    const also = ignored.length ? ` Also ignored: ${ignored.join("; ")}.` : "";
    showBanner(TITLES.link, `This preview link is too large or damaged: ${link.modelError}. Its settings are applied; drop “${name}” here to see the slice.${also}`);
  } else if (notice) {
    showBanner(notice.title, notice.message, notice.tone);
  }
  note(
    link.modelError
      ? `The model “${name}” (SHA-256 ${sha256.slice(0, 12)}…) could not be taken from the link. Drop that file here${at} with the link's settings.${extra}`
      : `This preview link is for “${name}” (SHA-256 ${sha256.slice(0, 12)}…), which was too big to put in the link. Drop that file here${at} with the link's settings.${extra}`,
    "warn",
  );
  setState("idle");
  updateButtons();
  return true;
}

// ---------------------------------------------------------------------------------------------
// events

function wire(): void {
  $("btn-sample").addEventListener("click", () => void openSample());
  $<HTMLInputElement>("file-input").addEventListener("change", (ev) => {
    const input = ev.target as HTMLInputElement;
    const f = input.files?.[0];
    input.value = "";
    if (f) void openFile(f);
  });
  $("btn-download").addEventListener("click", () => void download());
  $("btn-share").addEventListener("click", () => void share().catch(showError));
  $("btn-slice").addEventListener("click", () => model && void startSlice(model));
  $("btn-reset").addEventListener("click", () => form.reset());
  $("btn-cancel").addEventListener("click", () => {
    if (!busy) return;
    generation++;
    pool.cancel();
    busy = false;
    progress(null);
    setState("cancelled");
    showBanner("Slicing cancelled.", "Change the settings or open another file, then slice again.", "info");
    if (slice && !slice.complete) {
      slice = null;
      renderer.current = renderer.below = null;
      renderer.request();
      writeStats();
      layerLabel();
    }
    restoreModel();
    updateButtons();
  });
  $("banner-close").addEventListener("click", hideBanner);
  // the form is never submitted (Enter slices, below); no inline handler: the page's CSP
  $("settings").addEventListener("submit", (ev) => ev.preventDefault());
  $("settings").addEventListener("keydown", (ev) => {
    if ((ev as KeyboardEvent).key === "Enter" && model) {
      ev.preventDefault();
      void startSlice(model);
    }
  });

  slider.addEventListener("input", () => show(Number(slider.value)));
  $("btn-up").addEventListener("click", () => show(current + 1));
  $("btn-down").addEventListener("click", () => show(current - 1));
  $("btn-fit").addEventListener("click", fit);
  $<HTMLInputElement>("opt-travel").addEventListener("change", (ev) => {
    renderer.showTravel = (ev.target as HTMLInputElement).checked;
    $("legend-travel").hidden = !renderer.showTravel;
    renderer.request();
  });
  $<HTMLInputElement>("opt-voids").addEventListener("change", (ev) => {
    renderer.showVoids = (ev.target as HTMLInputElement).checked;
    $("legend-voids").hidden = !renderer.showVoids;
    if (slice) show(current);
    if (renderer.showVoids && slice) void analyseVoids(slice);
    renderer.request();
  });
  $("btn-worst").addEventListener("click", () => {
    if (slice?.worst) show(slice.worst.index);
  });
  $<HTMLInputElement>("opt-below").addEventListener("change", (ev) => {
    renderer.showBelow = (ev.target as HTMLInputElement).checked;
    $("legend-below").hidden = !renderer.showBelow;
    renderer.request();
  });

  document.addEventListener("keydown", (ev) => {
    const t = ev.target as HTMLElement;
    if (t === slider || t.closest("form, dialog") || t instanceof HTMLInputElement || t instanceof HTMLSelectElement) return;
    const step: Record<string, number> = { ArrowUp: 1, ArrowRight: 1, ArrowDown: -1, ArrowLeft: -1, PageUp: 10, PageDown: -10 };
    if (ev.key in step) show(current + step[ev.key]);
    else if (ev.key === "Home") show(0);
    else if (ev.key === "End") show(slice ? slice.layers - 1 : 0);
    else if (ev.key === "f" || ev.key === "F") fit();
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
      viewTouched = true;
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
    viewTouched = true;
  });
  const end = () => {
    drag = null;
    canvas.classList.remove("dragging");
  };
  canvas.addEventListener("pointerup", end);
  canvas.addEventListener("pointercancel", end);
  canvas.addEventListener("dblclick", fit);
  renderer.onDraw = () => {
    $("zoom").textContent = `${renderer.view.scale >= 10 ? Math.round(renderer.view.scale) : renderer.view.scale.toFixed(1)} px/mm`;
  };

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
    const f = ev.dataTransfer?.files[0];
    if (f) void openFile(f);
  });

  window.addEventListener("error", (ev) => showError(ev.error ?? ev.message));
  window.addEventListener("unhandledrejection", (ev) => {
    if (!(ev.reason instanceof Cancelled)) showError(ev.reason);
  });
}

function fit(): void {
  const s = slice;
  if (!s) return;
  const b = s.info.bounds;
  viewTouched = false;
  renderer.fit(b ? { minX: b.min[0], minY: b.min[1], maxX: b.max[0], maxY: b.max[1] } : s.bbox);
}

// hooks for the browser tests
declare global {
  interface Window {
    dropslice: unknown;
  }
}
window.dropslice = {
  status: () => ({
    state: document.body.dataset.state,
    layers: slice?.layers ?? 0,
    done: slice?.done ?? 0,
    complete: slice?.complete ?? false,
    layer: current,
    droplets: slice?.droplets ?? 0,
    counts: slice ? { ...slice.totals } : null,
    layerDroplets: slice?.counts[current] ?? null,
    view: { ...renderer.view },
    name: slice?.name ?? null,
    workers: pool.size,
    /** Seconds from the file chosen to every layer's G-code ready (the last finished slice). */
    seconds: slice?.seconds ?? null,
    cached: slice?.cache.size ?? 0,
    voids: renderer.showVoids,
    analysed: slice?.analysed ?? 0,
    worst: slice?.worst?.index ?? null,
    /** Whether the layer on the canvas carries its void mask. */
    masked: Boolean(renderer.current?.mask),
    /** Index of the layer on the canvas (null while it is being fetched). */
    shown: renderer.current?.index ?? null,
  }),
  crash: () => pool.crash().catch(showError),
  /** Draws now (synchronously), for timing. */
  redraw: () => renderer.draw(),
  setView: (v: View) => {
    renderer.view = { ...v };
    viewTouched = true;
    renderer.request();
  },
  show,
};

async function main(): Promise<void> {
  setState("loading");
  wire();
  try {
    init = await pool.init();
  } catch (e) {
    showError(e);
    return;
  }
  $("version").textContent = init.version;
  form = new SettingsForm($("settings"), init.schema, () => updateButtons());
  updateButtons();
  if (!(await openLink())) await openSample();
}

void main();

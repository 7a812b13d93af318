// The droplet calibration panel (docs/spec.md "Calibrating the droplet size from a printed part"):
// the measured mass of a printed part and the material's density, with the droplet count of
// the slice shown (its droplet total, H and droplet_aspect as sliced) or of the opened .gco
// file (its header's total, else its commands'; its header's H and aspect), give the core's
// effective droplet volume, cell B²H, filling degree and suggested droplet_aspect. Every figure
// is the core's (src/output/calibrate.rs, called in a worker: www/worker/calibration.ts); the page only checks
// that the inputs are positive numbers before asking and shows the answer or the core's refusal
// next to the inputs. "Use droplet_aspect = X" puts the suggestion into the settings form.
//
// The mass belongs to the code that was printed: the panel binds it to the droplet count, H
// and aspect of the code shown when the mass was typed, and keeps them when the same job is
// sliced again (a new slice is new code: its print must be weighed). After Use, it asks for
// the weight of a print of the new code instead of suggesting anything more from this mass.

import { Cancelled, SliceError } from "../core/client";
import type { Page } from "./page";
import type { CalibrateRequest, Calibration } from "../core/protocol";
import type { Slice } from "../core/store";
import { updateButtons } from "./controls";
import { $, nf, setText } from "./dom";

/** What the panel calibrates: a finished slice or an opened .gco file. */
interface Source {
  slice: Slice;
  /** One line naming it and the droplet size it was made with. */
  label: string;
  /** The density to prefill (g/cm³): the slice's material_density, the header's, or the default. */
  density: number;
  request(mass: number, density: number): CalibrateRequest;
}

/** The panel's state: the source it was set up for, the last answer, the request under way. */
const state = {
  slice: null as Slice | null,
  complete: false,
  droplets: NaN,
  source: null as Source | null,
  result: null as Calibration | null,
  /** The code the mass typed was measured on, and the job it was sliced of. */
  bound: null as { source: Source; job: unknown } | null,
  /** The value put into the settings by Use (null: none since the last input). */
  used: null as string | null,
  /** Bumped by every request and every new source: an older answer is dropped. */
  seq: 0,
  timer: 0,
};

/** Typing settles for this long before the core is asked. */
const DEBOUNCE_MS = 250;

/** A positive finite number from a text field, or a message saying what is wrong. */
export function positive(raw: string, what: string, unit: string): { value?: number; error?: string } {
  const t = raw.trim();
  if (t === "") return { error: `Type the ${what} in ${unit}.` };
  const v = Number(t);
  if (!Number.isFinite(v) || v <= 0) return { error: `The ${what} must be a number of ${unit} greater than 0 (got “${t}”).` };
  return { value: v };
}

const num = (v: unknown) => (typeof v === "number" ? v : Number(v));

/** The source of slice `s`, or null (with the reason shown instead). */
function sourceOf(page: Page, s: Slice | null): Source | string {
  if (!s || !s.complete) return "Slice a part or open its .gco file: its droplet count is the calibration's N.";
  const fallback = num(page.init?.defaults.material_density);
  if (s.source === "gco") {
    const g = s.gcodeFile;
    if (!g) return "The opened .gco file is no longer at hand: open it again.";
    const h = g.header;
    const density = num(h.material_density);
    const size = [h.layer_height ? `H ${h.layer_height} mm` : "no layer_height", h.droplet_aspect ? `droplet_aspect ${h.droplet_aspect}` : "droplet_aspect default"];
    return {
      slice: s,
      label: `${s.name} (header: ${size.join(", ")})`,
      density: Number.isFinite(density) && density > 0 ? density : fallback,
      request: (mass, density) => ({ from: "gcode", file: g.file, mass, density }),
    };
  }
  const droplets = s.figures.core?.droplets;
  if (droplets === undefined) return "The slice has no droplet total from the core yet.";
  const h = num(s.settings.layer_height);
  const aspect = num(s.settings.droplet_aspect);
  const density = num(s.settings.material_density);
  return {
    slice: s,
    label: `This slice: ${nf.format(droplets)} droplets, H ${h} mm, droplet_aspect ${aspect}`,
    density: Number.isFinite(density) && density > 0 ? density : fallback,
    request: (mass, density) => ({ from: "slice", droplets, layer_height: h, droplet_aspect: aspect, mass, density }),
  };
}

function input(id: string): HTMLInputElement {
  return $<HTMLInputElement>(id);
}

/** The message next to the inputs: a hint, a refusal (`bad`) or what was done (`ok`). */
function message(text: string, tone: "hint" | "bad" | "ok" = "hint"): void {
  const m = $("calib-message");
  setText("calib-message", text);
  m.className = `calib-message ${tone}`;
}

/** The panel's `data-state`: "pending" from an input until the answer (or the message) is
 *  shown, then "result", "refused" (a message of the checks or the core) or "idle". */
function settle(st: "pending" | "result" | "refused" | "idle"): void {
  $("calib").dataset.state = st;
}

function showResult(c: Calibration | null): void {
  state.result = c;
  $("calib-result").hidden = c === null;
  $("calib-explanation").hidden = c === null;
  $("calib-use").hidden = c === null;
  if (!c) return;
  const from = { header: "header", commands: "counted", given: "slice" }[c.count_source];
  setText("calib-droplets-label", `Droplets N (${from})`);
  setText("calib-droplets", nf.format(c.droplets));
  setText("calib-volume", `${c.droplet_volume_mm3.toFixed(5)} mm³`);
  setText("calib-cell", `${c.cell_volume_mm3.toFixed(5)} mm³`);
  setText("calib-filling", `${(100 * c.filling_degree).toFixed(1)} %`);
  setText("calib-now", String(c.current_droplet_aspect));
  setText("calib-aspect", suggestion(c));
  setText("calib-explanation", c.explanation);
  setText("calib-use", `Use droplet_aspect = ${suggestion(c)}`);
}

/** The suggested aspect as shown and as put into the form: three decimals (B to H/1000). */
function suggestion(c: Calibration): string {
  return c.suggested_droplet_aspect.toFixed(3);
}

/** Checks the inputs and asks the core (after [[DEBOUNCE_MS]] unless `now`). A mass typed
 *  (`mass`) is of the code shown now: the panel takes that code's figures. */
function schedule(page: Page, now = false, mass = false): void {
  clearTimeout(state.timer);
  state.used = null;
  if (mass) {
    const src = sourceOf(page, page.store.slice);
    if (typeof src !== "string") {
      state.source = src;
      setText("calib-source", src.label);
    }
  }
  state.seq++;
  settle("pending");
  if (now) void run(page);
  else state.timer = window.setTimeout(() => void run(page), DEBOUNCE_MS);
}

async function run(page: Page): Promise<void> {
  const src = state.source;
  const seq = ++state.seq;
  if (!src) {
    settle("idle");
    return showResult(null);
  }
  const mass = positive(input("calib-mass").value, "measured mass", "grams");
  const density = positive(input("calib-density").value, "density", "g/cm³");
  input("calib-mass").setAttribute("aria-invalid", String(Boolean(mass.error) && input("calib-mass").value.trim() !== ""));
  input("calib-density").setAttribute("aria-invalid", String(Boolean(density.error)));
  if (mass.value === undefined || density.value === undefined) {
    showResult(null);
    const empty = input("calib-mass").value.trim() === "";
    settle(mass.value === undefined && empty ? "idle" : "refused");
    if (mass.value === undefined) return message(mass.error!, empty ? "hint" : "bad");
    return message(density.error!, "bad");
  }
  message("Calculating…");
  try {
    const c = await page.actions.calibrate(src.request(mass.value, density.value));
    if (seq !== state.seq || state.source !== src) return;
    message("");
    state.bound = { source: src, job: page.store.job };
    showResult(c);
    settle("result");
  } catch (e) {
    if (seq !== state.seq || state.source !== src) return;
    showResult(null);
    settle("refused");
    if (e instanceof Cancelled) return message("The calculation was cancelled: type the mass again.");
    message(e instanceof SliceError || e instanceof Error ? e.message : String(e), "bad");
  }
}

/** Sets the panel up for the slice shown (called with the statistics; cheap when nothing
 *  changed): a new source prefills the density and recalculates for the mass typed. */
export function writeCalibration(page: Page): void {
  const s = page.store.slice;
  const droplets = s?.figures.core?.droplets ?? NaN;
  if (s === state.slice && (s?.complete ?? false) === state.complete && Object.is(droplets, state.droplets)) return;
  state.slice = s;
  state.complete = s?.complete ?? false;
  state.droplets = droplets;
  if (keepBound(page, s)) return;
  const src = sourceOf(page, s);
  clearTimeout(state.timer);
  state.seq++;
  showResult(null);
  const ready = typeof src !== "string";
  state.source = ready ? src : null;
  setText("calib-source", ready ? src.label : src);
  input("calib-mass").disabled = !ready;
  input("calib-density").disabled = !ready;
  if (!ready) {
    settle("idle");
    return message("");
  }
  input("calib-density").value = String(src.density);
  schedule(page, true);
}

/** A new slice of the job whose code the mass typed was measured on: the panel keeps that
 *  code's figures (and says so); after Use it asks for the new print's weight. Returns whether
 *  it kept them. */
function keepBound(page: Page, s: Slice | null): boolean {
  const b = state.bound;
  const typed = input("calib-mass").value.trim() !== "";
  if (!b || !typed || !s || s.source !== "stl" || b.source.slice.source !== "stl" || b.job !== page.store.job || s === b.source.slice) {
    if (!typed || (s && s !== b?.source.slice)) state.bound = null;
    return false;
  }
  if (!s.complete) return true;
  setText("calib-source", `The mass typed was measured on earlier code (${b.source.label.replace(/^This slice: /, "")}); the slice shown is new code.`);
  if (state.used !== null) {
    message(`droplet_aspect is now ${state.used}: print this new code, weigh the print and type its mass to check it.`, "ok");
  }
  return true;
}

/** The suggestion into the settings form (the user slices again). */
function use(page: Page): void {
  const c = state.result;
  const form = page.form;
  if (!c || !form) return;
  const value = suggestion(c);
  form.set({ droplet_aspect: Number(value) });
  updateButtons(page);
  page.actions.settingsEdited();
  const field = document.getElementById("set-droplet_aspect");
  field?.closest("details")?.setAttribute("open", "");
  field?.scrollIntoView({ block: "nearest" });
  const again = page.store.job ? "press Slice to slice again" : "open the model and slice it";
  // this mass was of the code before: no more suggestions from it
  state.used = value;
  clearTimeout(state.timer);
  state.seq++;
  showResult(null);
  settle("idle");
  message(`droplet_aspect is now ${value} in the settings: ${again}, then print the new code, weigh the print and type its mass here.`, "ok");
}

export function wireCalibrate(page: Page): void {
  for (const id of ["calib-mass", "calib-density"]) {
    const el = input(id);
    const mass = id === "calib-mass";
    el.addEventListener("input", () => schedule(page, false, mass));
    el.addEventListener("keydown", (ev) => {
      if (ev.key === "Enter") {
        ev.preventDefault();
        schedule(page, true, mass);
      }
    });
  }
  $("calib-use").addEventListener("click", () => use(page));
  writeCalibration(page);
}

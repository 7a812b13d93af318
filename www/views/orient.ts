// The selected part's orientations (the parts panel's "Orient"): the core's best few
// candidates by the overhang rule, each with its unsupported area and height, the part's
// current one marked; picking one turns the part (an action: one undoable part edit). While
// the core compares them a Cancel button stops it (the job worker is replaced); the box's
// `data-state` says where it is: running, done, cancelled or error.

import { Cancelled } from "../core/client";
import type { Orientation, Orientations } from "../core/protocol";
import type { Part } from "../core/job";
import { $ } from "./dom";
import type { Page } from "./page";

/** Candidates shown. */
const SHOWN = 5;

/** The part whose candidates are shown (null: none) and the candidates listed. */
let shownFor: number | null = null;
let listed: Orientation[] = [];
/** The latest request (a later one, or a Cancel, makes an earlier answer moot). */
let latest = 0;

const deg = (v: number) => `${+v.toFixed(1)}°`;
/** An area or a height: one decimal; from 10⁹ on (a file in the wrong units) 4 significant
 *  digits with a power of ten, never a line of digits. */
const figure = (v: number) => (Math.abs(v) >= 1e9 ? v.toExponential(3) : v.toFixed(1));

function setState(state: "running" | "done" | "cancelled" | "error"): void {
  $("orient-box").dataset.state = state;
  $("orient-cancel").hidden = state !== "running";
}
const same = (a: Orientation, b: { rotate_x: number; rotate_y: number; rotate_z: number }) =>
  Math.abs(a.rotate_x - b.rotate_x) < 1e-6 && Math.abs(a.rotate_y - b.rotate_y) < 1e-6 && Math.abs(a.rotate_z - b.rotate_z) < 1e-6;

function status(text: string, bad = false): void {
  $("orient-box").hidden = false;
  $("orient-status").textContent = text;
  $("orient-status").classList.toggle("bad", bad);
}

/** Whether the worker's answer has the shape and finite figures the list needs. */
function usable(o: unknown): o is Orientations {
  const ok = (c: unknown): boolean => {
    const x = c as Orientation | null;
    return typeof x === "object" && x !== null && [x.rotate_x, x.rotate_y, x.rotate_z, x.unsupported_area, x.height].every((v) => typeof v === "number" && Number.isFinite(v));
  };
  const r = o as Orientations | null;
  return typeof r === "object" && r !== null && ok(r.current) && Array.isArray(r.candidates) && r.candidates.length > 0 && r.candidates.every(ok);
}

/** Asks for the part's orientations and lists them. */
export async function orientPart(page: Page, part: Part): Promise<void> {
  const id = part.id;
  const run = ++latest;
  shownFor = id;
  listed = [];
  $("orient-list").replaceChildren();
  status("Comparing orientations…");
  setState("running");
  let answer: unknown;
  try {
    answer = await page.actions.orient(id);
  } catch (e) {
    if (run !== latest || shownFor !== id) return;
    if (e instanceof Cancelled) {
      setState("cancelled");
      status("Cancelled: the part is as it was. Orient compares its orientations again.");
      return;
    }
    setState("error");
    status(`Could not compare orientations: ${(e as { message?: string })?.message ?? String(e)}`, true);
    return;
  }
  if (run !== latest || shownFor !== id) return;
  if (!usable(answer)) {
    setState("error");
    return status("Could not compare orientations: the answer had no usable candidates. Try again, or reload the page.", true);
  }
  setState("done");
  const best = answer.candidates[0];
  status(`Best first by unsupported area (the overhang rule, from the facets). Now: ${figure(answer.current.unsupported_area)} mm²${best.unsupported_area < answer.current.unsupported_area ? `; best: ${figure(best.unsupported_area)} mm²` : ", already the least"}.`);
  renderCandidates(page, part, answer.candidates.slice(0, SHOWN));
}

/** Cancel: the comparison under way stops (its answer never comes); the part is unchanged. */
export function cancelOrient(page: Page): void {
  if ($("orient-box").dataset.state !== "running") return;
  $("orient-cancel").hidden = true;
  status("Cancelling…");
  page.actions.cancelOrient();
}

function renderCandidates(page: Page, part: Part, list: Orientation[]): void {
  listed = list;
  const items = list.map((c, i) => {
    const li = document.createElement("li");
    const b = document.createElement("button");
    b.type = "button";
    b.className = "btn orient-pick";
    b.dataset.index = String(i);
    const current = same(c, part.spec);
    b.setAttribute("aria-current", String(current));
    const head = document.createElement("span");
    head.textContent = `${i + 1}. x ${deg(c.rotate_x)} · y ${deg(c.rotate_y)} · z ${deg(c.rotate_z)}`;
    const mark = document.createElement("span");
    mark.className = "orient-mark";
    mark.textContent = current ? "current" : "";
    const figures = document.createElement("span");
    figures.className = "orient-figures";
    figures.textContent = `${figure(c.unsupported_area)} mm² unsupported · ${figure(c.height)} mm high`;
    b.append(head, mark, figures);
    b.title = current ? "The part's orientation now" : "Turn the part to this orientation";
    b.addEventListener("click", () => {
      void page.actions.applyOrientation(part.id, c);
    });
    li.append(b);
    return li;
  });
  $("orient-list").replaceChildren(...items);
}

/** The editor shows `part` (after any edit, undo or redo): the current one marked again;
 *  another part (or none): the list goes. */
export function orientEditorShows(page: Page, part: Part | undefined): void {
  if (part && part.id === shownFor) {
    if (listed.length) renderCandidates(page, part, listed);
    return;
  }
  shownFor = null;
  listed = [];
  latest++;
  setState("done");
  $("orient-box").hidden = true;
  $("orient-list").replaceChildren();
}

// The parts panel (left column, above the settings): the job's parts (name, triangles, size on
// the plate, copies; a context menu, views/contextmenu.ts), the selected part's editor
// (rotation, scale with a uniform lock, the size in mm per axis — typing one scales the part to
// it —, mirror per axis, place or "auto", place angle, copies, lay flat, duplicate, remove) and
// the job's buttons (add part,
// arrange, save job). Every change is an action (flows/job.ts), which has the core lay the job out
// again; what is shown comes from the job and the core's layout only.

import { fitsPart, partName, partNumber, partRangeWords, type Changes, type Part } from "../core/job";
import { jobMisfits, plainJobMessage, type OffPlate } from "../core/plate";
import type { JobSchema } from "../core/protocol";
import type { Page, PartsView } from "./page";
import { $, nf } from "./dom";
import { PART_KEYS } from "../core/settings";
import { MAX_UNITS, unitIndices, unitRole, unitsOf } from "../core/units";
import { cancelOrient, orientEditorShows, orientPart } from "./orient";
import { mirrorChange, openPartMenu } from "./contextmenu";

/** The panel's number fields (index.html `#part-<key>`): the part keys of the settings table,
 *  and `copies`. */
const NUMBER_FIELDS = [...PART_KEYS, "copies"] as const;
type NumberField = (typeof NUMBER_FIELDS)[number];

const fmt = (v: number) => String(+v.toFixed(4));
const mm = (v: number) => v.toFixed(1);

const AXES = ["x", "y", "z"] as const;
const SIZE_HELP = "Type a size in mm (100 or 100mm): the part is scaled to it";
type Axis = (typeof AXES)[number];

/** A size typed in mm ("100", "100mm", "100 mm", "99,5"): the millimetres, or why not. */
export function parseSize(raw: string): { value?: number; error?: string } {
  const t = raw.trim().replace(",", ".").replace(/\s*mm$/i, "");
  const x = Number(t);
  if (t === "" || !Number.isFinite(x)) return { error: "a size in mm is needed (e.g. 100 or 100mm)" };
  if (!(x > 0)) return { error: "the size must be > 0 mm" };
  return { value: x };
}

/** The scales that make the part `size` mm along `axis` (all three with the uniform lock), from
 *  its scale now and its size now along that axis (the core's `Instance.size`); or why not (a
 *  scale out of the core's range). */
export function scaleTo(spec: Part["spec"], now: number, axis: Axis, size: number, uniform: boolean, job: JobSchema): { changes?: Changes; error?: string } {
  if (!(now > 0)) return { error: "the part has no size along this axis" };
  const f = size / now;
  const keys = uniform ? AXES.map((a) => `scale_${a}` as const) : [`scale_${axis}` as const];
  const changes: Changes = {};
  for (const k of keys) {
    const v = +(spec[k] * f).toPrecision(12);
    const range = partNumber(job, k);
    if (!range || !fitsPart(range, v)) return { error: `that needs a scale of ${fmt(v)}, but the scale must be ${range ? partRangeWords(range) : "in range"}` };
    changes[k] = v;
  }
  return { changes };
}

/** A number typed into a field ("0,5" too): the value, or why not (its range is the core's:
 *  `job`, the core's job schema). */
function parseField(k: NumberField, raw: string, job: JobSchema): { value?: number; error?: string } {
  const x = Number(raw.trim().replace(",", "."));
  if (raw.trim() === "" || !Number.isFinite(x)) return { error: "a number is needed" };
  const spec = partNumber(job, k);
  if (!spec) return { error: `${k} is not a number of a part` };
  if (!fitsPart(spec, x)) return { error: partRangeWords(spec) };
  return { value: x };
}

export class PartsPanel implements PartsView {
  constructor(private readonly page: Page) {}

  /** Wires the panel's inputs and buttons (once). */
  wire(): void {
    const { actions } = this.page;
    for (const k of NUMBER_FIELDS) {
      const input = $<HTMLInputElement>(`part-${k}`);
      input.addEventListener("change", () => this.changed(k, input));
      input.addEventListener("keydown", (ev) => {
        if (ev.key === "Enter") {
          ev.preventDefault();
          this.changed(k, input);
        }
      });
    }
    $<HTMLInputElement>("part-auto").addEventListener("change", (ev) => {
      const p = this.part();
      if (!p) return;
      const auto = (ev.target as HTMLInputElement).checked;
      if (auto) void this.edit(p, { place: null });
      else {
        const at = this.at(p);
        if (at) void this.edit(p, { place_x: +at[0].toFixed(2), place_y: +at[1].toFixed(2) });
      }
    });
    $<HTMLSelectElement>("part-unit").addEventListener("change", (ev) => {
      const p = this.part();
      const unit = Number((ev.target as HTMLSelectElement).value);
      // the core checks the unit against the machine's `units` (a refusal puts the choice back)
      if (p && Number.isInteger(unit) && unit >= 0 && unit < MAX_UNITS && unit !== p.spec.unit) void this.edit(p, { unit }).then((ok) => ok || this.renderEditor());
    });
    for (const a of AXES) {
      const input = $<HTMLInputElement>(`part-size_${a}`);
      const go = () => this.sized(a, input);
      input.addEventListener("change", go);
      input.addEventListener("keydown", (ev) => {
        if (ev.key === "Enter") {
          ev.preventDefault();
          go();
        }
      });
      $(`part-mirror_${a}`).addEventListener("click", () => {
        const p = this.part();
        if (p) void this.edit(p, mirrorChange(p, a));
      });
    }
    $("part-lay-flat").addEventListener("click", () => this.part() && actions.layFlat(this.part()!.id));
    $("part-orient").addEventListener("click", () => this.part() && void orientPart(this.page, this.part()!));
    $("orient-cancel").addEventListener("click", () => cancelOrient(this.page));
    $("part-duplicate").addEventListener("click", () => this.part() && actions.duplicatePart(this.part()!.id));
    $("part-remove").addEventListener("click", () => this.part() && actions.removePart(this.part()!.id));
    $("btn-arrange").addEventListener("click", () => actions.arrangeAll());
    $("btn-save-job").addEventListener("click", () => actions.saveJob());
  }

  /** The part the editor edits: the selected one, or the only one. */
  part(): Part | undefined {
    const job = this.page.store.job;
    if (!job) return undefined;
    return job.part(job.selected) ?? (job.parts.length === 1 ? job.parts[0] : undefined);
  }

  /** Where the part's first copy is (the core's layout). */
  private at(p: Part): [number, number] | null {
    const job = this.page.store.job!;
    const inst = job.layout?.instances.find((x) => job.parts[x.part] === p && x.copy === 0);
    return inst ? inst.at : null;
  }

  private edit(p: Part, changes: Changes): Promise<boolean> {
    return this.page.actions.editParts([{ id: p.id, changes }]);
  }

  /** The part's size (mm) now along `axis`, before the rotation on the plate (its first copy in
   *  the core's layout). */
  private size(p: Part, axis: Axis): number | null {
    const job = this.page.store.job!;
    const inst = job.layout?.instances.find((x) => job.parts[x.part] === p && x.copy === 0);
    return inst?.size ? inst.size[AXES.indexOf(axis)] : null;
  }

  /** A size typed into a size field (or "…mm" into a scale field): the part scaled to it. */
  private sized(axis: Axis, input: HTMLInputElement): void {
    const p = this.part();
    if (!p) return;
    if (input.value === input.dataset.shown) {
      input.setAttribute("aria-invalid", "false");
      input.title = SIZE_HELP;
      return;
    }
    const now = this.size(p, axis);
    let r: { changes?: Changes; error?: string } = parseSize(input.value);
    if (r.error === undefined) {
      r = now === null ? { error: "the part has no layout yet" } : scaleTo(p.spec, now, axis, (r as { value: number }).value, $<HTMLInputElement>("part-scale-lock").checked, this.page.init!.job);
    }
    input.setAttribute("aria-invalid", r.error ? "true" : "false");
    input.title = r.error ?? "";
    if (r.changes) void this.edit(p, r.changes).then((ok) => ok || this.renderEditor());
  }

  private changed(k: NumberField, input: HTMLInputElement): void {
    const p = this.part();
    if (!p) return;
    // the text the editor wrote, left as it was (a change event on leaving a field the editor
    // wrote into): no edit, so a value shown rounded is never taken rounded
    if (input.value === input.dataset.shown) {
      input.setAttribute("aria-invalid", "false");
      input.title = "";
      return;
    }
    if (k.startsWith("scale_") && /mm\s*$/i.test(input.value)) {
      // "100mm" in a scale field: a size
      this.sized(k.slice(-1) as Axis, input);
      return;
    }
    const r = parseField(k, input.value, this.page.init!.job);
    input.setAttribute("aria-invalid", r.error ? "true" : "false");
    input.title = r.error ?? "";
    if (r.value === undefined) return;
    const v = r.value;
    if ((k === "place_x" || k === "place_y") && (p.spec.place_x === undefined || p.spec.place_y === undefined)) {
      // placing one axis of an arranged part keeps the other where the arrangement put it
      const at = this.at(p) ?? [0, 0];
      const other = k === "place_x" ? { place_y: +at[1].toFixed(2) } : { place_x: +at[0].toFixed(2) };
      void this.edit(p, { [k]: v, ...other });
      return;
    }
    if (k.startsWith("scale") && $<HTMLInputElement>("part-scale-lock").checked) {
      const f = v / p.spec[k as "scale_x"];
      void this.edit(p, { scale_x: p.spec.scale_x * f, scale_y: p.spec.scale_y * f, scale_z: p.spec.scale_z * f });
      return;
    }
    if (v !== p.spec[k]) void this.edit(p, { [k]: v });
  }

  /** Redraws the list and the editor from the job. */
  render(): void {
    const { store } = this.page;
    const job = store.job;
    $("parts-panel").hidden = !job;
    if (!job) return;
    const list = $("part-list");
    const misfits = jobMisfits(job, this.page.form?.values());
    const off = misfits.filter((o) => o.blocks);
    const items = job.parts.map((p, i) => {
      const li = document.createElement("li");
      li.className = "part-item";
      li.dataset.id = String(p.id);
      li.setAttribute("aria-selected", String(job.selected === p.id));
      li.toggleAttribute("data-off-plate", off.some((o) => o.part === i));
      li.tabIndex = 0;
      const name = document.createElement("span");
      name.className = "part-name";
      name.textContent = partName(job, p);
      name.title = name.textContent;
      const meta = document.createElement("span");
      meta.className = "part-meta";
      const m = job.models.get(p.spec.file);
      const tris = p.spec.item !== undefined ? m?.info.items[p.spec.item]?.triangles : m?.info.triangles;
      const inst = job.layout?.instances.find((x) => x.part === i && x.copy === 0);
      const size = inst ? `${mm(inst.max[0] - inst.min[0])} × ${mm(inst.max[1] - inst.min[1])} × ${mm(inst.max[2] - inst.min[2])} mm` : "";
      meta.textContent = [tris !== undefined ? `${nf.format(tris)} triangles` : "", size].filter(Boolean).join(" · ");
      const copies = document.createElement("span");
      copies.className = "part-copies";
      copies.textContent = p.spec.copies > 1 ? `× ${p.spec.copies}` : "";
      const unit = document.createElement("span");
      unit.className = "part-unit";
      unit.textContent = p.spec.unit > 0 ? `unit ${p.spec.unit}` : "";
      unit.title = p.spec.unit > 0 ? `Printed by discharge unit ${p.spec.unit}` : "";
      const right = document.createElement("span");
      right.className = "part-tags";
      right.append(unit, copies);
      li.append(name, right, meta);
      const pick = () => this.page.actions.selectPart(p.id);
      li.addEventListener("click", pick);
      // the part's context menu: right-click, the ContextMenu key or Shift+F10; the focus
      // comes back to the part's line (made again by then: found by its id)
      const back = () => list.querySelector<HTMLElement>(`li[data-id="${p.id}"]`);
      li.addEventListener("contextmenu", (ev) => {
        ev.preventDefault();
        const keyboard = ev.button !== 2 && ev.clientX === 0 && ev.clientY === 0;
        const r = li.getBoundingClientRect();
        openPartMenu(this.page, p.id, keyboard ? r.left + 12 : ev.clientX, keyboard ? r.bottom : ev.clientY, back);
      });
      li.addEventListener("keydown", (ev) => {
        if (ev.key === "Enter" || ev.key === " ") {
          ev.preventDefault();
          pick();
        } else if (ev.key === "ContextMenu" || (ev.key === "F10" && ev.shiftKey)) {
          ev.preventDefault();
          const r = li.getBoundingClientRect();
          openPartMenu(this.page, p.id, r.left + 12, r.bottom, back);
        }
      });
      return li;
    });
    // a part's line that had the focus keeps it (an edit draws the list again)
    const focused = list.contains(document.activeElement) ? (document.activeElement as HTMLElement).closest<HTMLElement>("li")?.dataset.id : undefined;
    list.replaceChildren(...items);
    if (focused !== undefined) list.querySelector<HTMLElement>(`li[data-id="${focused}"]`)?.focus({ preventScroll: true });
    // the core's sentence for each part off the plate, with a button per remedy; its other
    // warnings reworded
    const box = $("parts-warnings");
    const notes = misfits.map((o) => this.misfitNote(o));
    const others = (job.layout?.warnings ?? []).map(plainJobMessage);
    if (others.length) notes.push(Object.assign(document.createElement("span"), { textContent: others.join(" ") }));
    box.classList.toggle("bad", off.length > 0);
    box.hidden = notes.length === 0;
    box.replaceChildren(...notes);
    this.renderEditor();
  }

  /** A misfit's sentence and its buttons: *Turn 90° to fit*, *Scale to fit (N %)* — each one
   *  undoable edit of the part. */
  private misfitNote(o: OffPlate): HTMLElement {
    const note = document.createElement("p");
    note.className = "misfit";
    note.dataset.part = String(o.part);
    note.append(Object.assign(document.createElement("span"), { textContent: o.message }));
    const job = this.page.store.job;
    const p = job?.parts[o.part];
    if (!p) return note;
    const button = (id: string, text: string, changes: Changes) => {
      const b = document.createElement("button");
      b.type = "button";
      b.className = "btn small";
      b.dataset.fit = id;
      b.textContent = text;
      b.addEventListener("click", () => void this.edit(p, changes));
      note.append(" ", b);
    };
    if (o.turn !== null) button("turn", "Turn 90° to fit", { rotate_z: o.turn });
    else if (o.scale !== null && o.scaleTo) {
      const [scale_x, scale_y, scale_z] = o.scaleTo;
      button("scale", `Scale to fit (${o.scale} %)`, { scale_x, scale_y, scale_z });
    }
    return note;
  }

  renderEditor(): void {
    const p = this.part();
    const editor = $("part-editor");
    editor.hidden = !p;
    orientEditorShows(this.page, p);
    if (!p) return;
    const job = this.page.store.job!;
    $("part-editor-title").textContent = partName(job, p);
    const at = this.at(p);
    const auto = p.spec.place_x === undefined || p.spec.place_y === undefined;
    // an arranged part shows where the core put it
    const place = { place_x: auto ? (at?.[0] ?? 0) : p.spec.place_x!, place_y: auto ? (at?.[1] ?? 0) : p.spec.place_y! };
    const values: Record<NumberField, number> = { ...p.spec, ...place };
    for (const k of NUMBER_FIELDS) {
      const input = $<HTMLInputElement>(`part-${k}`);
      const text = k.startsWith("place_") && k !== "place_angle" ? values[k].toFixed(2) : fmt(values[k]);
      if (input.value !== text) input.value = text;
      input.dataset.shown = text;
      input.setAttribute("aria-invalid", "false");
      input.title = "";
    }
    for (const a of AXES) {
      const input = $<HTMLInputElement>(`part-size_${a}`);
      const size = this.size(p, a);
      const text = size === null ? "" : size.toFixed(2);
      if (input.value !== text) input.value = text;
      input.dataset.shown = text;
      input.setAttribute("aria-invalid", "false");
      input.title = SIZE_HELP;
      $(`part-mirror_${a}`).setAttribute("aria-pressed", String(p.spec[`mirror_${a}`]));
    }
    $<HTMLInputElement>("part-auto").checked = auto;
    this.renderUnits(p.spec.unit);
    $("part-place-row").classList.toggle("auto", auto);
    ($("part-remove") as HTMLButtonElement).disabled = job.parts.length <= 1;
  }

  /** The unit choice: one option per unit of the machine (the form's `units`), and the part's
   *  own unit when the machine has not that many (the core refuses the job then: the user
   *  picks another); hidden with one unit. */
  private renderUnits(unit: number): void {
    const n = unitsOf(this.page.form?.values());
    const select = $<HTMLSelectElement>("part-unit");
    const want = unitIndices(Math.max(n, unit + 1)).map((u) => `${u}:${u < n ? `Unit ${u} (${unitRole(u)})` : `Unit ${u} (the machine has ${n === 1 ? "one unit" : `units 0 … ${n - 1}`})`}`);
    if (select.dataset.options !== want.join("|")) {
      select.dataset.options = want.join("|");
      select.replaceChildren(...want.map((w) => new Option(w.slice(w.indexOf(":") + 1), w.slice(0, w.indexOf(":")))));
    }
    select.value = String(unit);
    select.hidden = $("part-unit-label").hidden = n === 1 && unit === 0;
  }
}

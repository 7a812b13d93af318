// The settings form, generated from the core's schema (settings_schema()). The page's relaxed
// text input ("0,2", " 3 ") is translated into the strict values the core expects in one place
// (core/settings.ts parse), and invalid values are flagged before anything is sliced.

import { isSettingName, parse, put, type RawSettings, type SettingName, type Settings, type SomeSettings, type Spec, type Value } from "../core/settings";
import { unitOfSetting } from "../core/units";

const OPEN_GROUPS = new Set(["Droplet", "Contours", "Fill"]);

function fmt(v: Value): string {
  return typeof v === "number" ? String(+v.toPrecision(12)) : String(v);
}

interface Field {
  spec: Spec;
  input: HTMLInputElement | HTMLSelectElement;
  row: HTMLElement;
  message: HTMLElement;
  error?: string;
  value: Value;
}

/** The group a setting is shown in: a unit's own settings (`unitN_<name>`) under "Unit N",
 *  whatever group the schema gives them; the others in the schema's. */
export function groupOf(spec: Spec): string {
  const u = unitOfSetting(spec.name);
  return u === null ? spec.group : `Unit ${u}`;
}

/** The unit N of a group "Unit N" (null: not a unit's group). */
const groupUnit = (group: string): number | null => {
  const m = /^Unit ([1-9][0-9]*)$/.exec(group);
  return m ? Number(m[1]) : null;
};

export class SettingsForm {
  private fields = new Map<SettingName, Field>();
  /** The groups' `<details>`, by name. */
  private groups = new Map<string, HTMLDetailsElement>();

  constructor(
    container: HTMLElement,
    readonly schema: readonly Spec[],
    private onChange: () => void,
  ) {
    container.replaceChildren();
    const groups = new Map<string, HTMLElement>();
    for (const spec of schema) {
      // a part's keys (the schema flags them) stay at their defaults, not shown: the parts
      // panel has them
      if (spec.part) {
        this.build(spec);
        continue;
      }
      const group = groupOf(spec);
      let body = groups.get(group);
      if (!body) {
        const details = document.createElement("details");
        details.className = "group";
        details.open = OPEN_GROUPS.has(group);
        const summary = document.createElement("summary");
        summary.textContent = group;
        details.append(summary);
        body = document.createElement("div");
        body.className = "group-body";
        details.append(body);
        container.append(details);
        groups.set(group, body);
        this.groups.set(group, details);
      }
      body.append(this.build(spec));
    }
  }

  /** Shows the settings of units 0 … n − 1 only: a group "Unit N" and every `unitN_` row
   *  with N ≥ n are hidden (their values stay, and go to the core as they are). */
  showUnits(n: number): void {
    for (const [group, details] of this.groups) {
      const u = groupUnit(group);
      details.hidden = u !== null && u >= n;
    }
    for (const f of this.fields.values()) {
      const u = unitOfSetting(f.spec.name);
      if (u !== null) f.row.hidden = u >= n;
    }
  }

  private build(spec: Spec): HTMLElement {
    const row = document.createElement("div");
    row.className = "field";
    row.title = spec.description;
    const id = `set-${spec.name}`;
    const label = document.createElement("label");
    label.htmlFor = id;
    label.textContent = spec.name.replace(/_/g, " ");
    let input: HTMLInputElement | HTMLSelectElement;
    if (spec.kind === "enum") {
      const sel = document.createElement("select");
      for (const c of spec.choices) sel.add(new Option(c.replace(/_/g, " "), c));
      input = sel;
    } else {
      const inp = document.createElement("input");
      if (spec.kind === "order") {
        // a choice from the list, or an order typed ("2,0,1")
        const list = document.createElement("datalist");
        list.id = `choices-${spec.name}`;
        for (const c of spec.choices) list.append(new Option(c.replace(/_/g, " "), c));
        row.append(list);
        inp.setAttribute("list", list.id);
      }
      if (spec.kind === "bool") inp.type = "checkbox";
      else {
        inp.type = "text";
        inp.inputMode = spec.kind === "integer" ? "numeric" : spec.kind === "order" ? "text" : "decimal";
        inp.autocomplete = "off";
        inp.spellcheck = false;
      }
      input = inp;
    }
    input.id = id;
    input.name = spec.name;
    const unit = document.createElement("span");
    unit.className = "unit";
    unit.textContent = spec.unit;
    const control = document.createElement("div");
    control.className = "control";
    control.append(input, unit);
    const message = document.createElement("div");
    message.className = "message";
    const help = document.createElement("div");
    help.className = "help";
    const range = spec.min !== null && spec.max !== null ? ` (${spec.min_exclusive ? ">" : ""}${spec.min} … ${spec.max})` : "";
    help.textContent = spec.description + range;
    row.append(label, control, message, help);
    const field: Field = { spec, input, row, message, value: spec.default };
    this.fields.set(spec.name, field);
    this.write(field, spec.default);
    const update = () => {
      this.read(field);
      this.onChange();
    };
    input.addEventListener("input", update);
    input.addEventListener("change", update);
    return row;
  }

  private write(f: Field, v: Value): void {
    if (f.input instanceof HTMLInputElement && f.input.type === "checkbox") f.input.checked = Boolean(v);
    else f.input.value = fmt(v);
    this.read(f);
  }

  private read(f: Field): void {
    const raw = f.input instanceof HTMLInputElement && f.input.type === "checkbox" ? f.input.checked : f.input.value;
    const r = parse(f.spec, raw);
    f.error = r.error;
    if (r.value !== undefined) f.value = r.value;
    f.row.classList.toggle("invalid", Boolean(r.error));
    f.row.classList.toggle("changed", !r.error && f.value !== f.spec.default);
    f.input.setAttribute("aria-invalid", r.error ? "true" : "false");
    f.message.textContent = r.error ?? "";
  }

  /** Names and messages of invalid fields. */
  errors(): { name: string; message: string }[] {
    return [...this.fields.values()].filter((f) => f.error).map((f) => ({ name: f.spec.name, message: f.error! }));
  }

  /** Every setting, in the schema's order (the core checked at init that it is the table's:
   *  core/settings.ts `checkInit`). */
  values(): Settings {
    const out: SomeSettings = {};
    for (const [name, f] of this.fields) put(out, name, f.value);
    return out as Settings;
  }

  /** Only the settings that differ from the defaults (for links). */
  changed(): SomeSettings {
    const out: SomeSettings = {};
    for (const [name, f] of this.fields) if (f.value !== f.spec.default) put(out, name, f.value);
    return out;
  }

  json(): string {
    return JSON.stringify(this.values());
  }

  /** Applies values (unknown names are ignored and returned). */
  set(values: SomeSettings): void {
    for (const [name, v] of Object.entries(values)) {
      const f = isSettingName(name) ? this.fields.get(name) : undefined;
      if (f && v !== undefined) this.write(f, v);
    }
  }

  /** Applies values from outside (unknown names are ignored and returned). */
  setRaw(values: RawSettings): string[] {
    const unknown: string[] = [];
    for (const [name, v] of Object.entries(values)) {
      const f = isSettingName(name) ? this.fields.get(name) : undefined;
      if (f) this.write(f, v);
      else unknown.push(name);
    }
    return unknown;
  }

  reset(): void {
    for (const f of this.fields.values()) this.write(f, f.spec.default);
    this.onChange();
  }

  /** A setting's value (every name of the table has a field). */
  get<K extends SettingName>(name: K): Settings[K] {
    return this.fields.get(name)!.value as Settings[K];
  }

  focusFirstError(): void {
    const f = [...this.fields.values()].find((x) => x.error);
    if (f) {
      // a unit's settings hidden by `units` are shown while they need fixing
      f.row.hidden = false;
      (f.row.closest("details") as HTMLDetailsElement | null)?.removeAttribute("hidden");
      (f.row.closest("details") as HTMLDetailsElement | null)?.setAttribute("open", "");
      f.input.focus();
    }
  }
}

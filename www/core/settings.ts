// The settings as the page holds them. Their names, kinds and defaults are the core's settings
// table (src/base/settings/table.rs), generated into settings.gen.ts: `Settings` (every
// setting, typed), `SettingName`, the part keys, the units' own keys. Values from outside (a
// link, a job file, a profile, local storage) arrive as `RawSettings` — any names, any values —
// and become `SomeSettings` only once checked against the core's schema. `parse` is the one
// place where the page's relaxed text input ("0,2", " 3 ") becomes the strict value the core
// expects (views/form.ts shows the result).

import type { InitResult, SettingSpec } from "./protocol";
import { DEFAULTS, PART_KEYS, SETTING_NAMES, UNIT_KEYS, type PartKey, type SettingName, type Settings, type UnitKey } from "./settings.gen";

export { DEFAULTS, MAX_UNITS, PART_KEYS, SETTING_NAMES, UNIT_KEYS } from "./settings.gen";
export type { PartKey, SettingName, Settings, UnitKey } from "./settings.gen";

export type Value = number | boolean | string;

/** Some settings, each checked against its kind and range (the ones that differ from the
 *  defaults, a profile's, a link's once checked). */
export type SomeSettings = Partial<Settings>;

/** Settings as they arrive from outside (`{name: value}`: a job file's, a link's, a .gco
 *  header's): names not checked here (the form ignores and names those it does not know; the
 *  core checks them all again). */
export type RawSettings = Readonly<Record<string, Value>>;

/** The core's schema row of a setting: a `SettingSpec` whose name is one of the table's. */
export type Spec = SettingSpec & { readonly name: SettingName };

/** The core's answer to `init` as the page uses it: its schema and defaults typed by the table. */
export type PageInit = Omit<InitResult, "schema" | "defaults"> & { schema: Spec[]; defaults: Readonly<Settings> };

const NAMES: ReadonlySet<string> = new Set(SETTING_NAMES);
const UNIT_KEY_SET: ReadonlySet<string> = new Set(UNIT_KEYS);
const PART_KEY_SET: ReadonlySet<string> = new Set(PART_KEYS);

export const isSettingName = (name: string): name is SettingName => NAMES.has(name);
/** Whether `name` is one of unit 0's settings that each unit has (`droplet_aspect`, …). */
export const isUnitKey = (name: string): name is UnitKey => UNIT_KEY_SET.has(name);
export const isPartKey = (name: string): name is PartKey => PART_KEY_SET.has(name);

/** Sets `out[name]` to `v`, a value the caller checked against the setting's kind (`parse`,
 *  the schema): the one place a value typed by kind becomes a value typed by name. */
export function put(out: SomeSettings, name: SettingName, v: Value): void {
  (out as Record<SettingName, Value>)[name] = v;
}

/** The core's `init` answer typed by the table: its schema must be the table's settings in
 *  the table's order and its defaults the table's (the page and its core are one build;
 *  anything else is a page built against another core, refused with the difference). */
export function checkInit(init: InitResult): PageInit {
  const names = init.schema.map((s) => s.name);
  const odd = names.find((n) => !NAMES.has(n)) ?? SETTING_NAMES.find((n) => !names.includes(n));
  if (odd !== undefined || names.length !== SETTING_NAMES.length) {
    throw new Error(`the page and its core are of different builds: the core's settings differ from the page's${odd ? ` (${odd})` : ""}; reload the page`);
  }
  // the schema gives every default (`init.defaults`, the core's settings as it writes them,
  // leaves out those of a machine of more than two units)
  const changed = init.schema.find((s) => s.default !== DEFAULTS[s.name as SettingName]);
  if (changed !== undefined) throw new Error(`the page and its core are of different builds: the default of ${changed.name} differs; reload the page`);
  return { ...init, schema: init.schema as Spec[], defaults: DEFAULTS };
}

/** The settings of `values` that differ from their defaults, in the table's order (what a job
 *  file, a link and the page's memory keep). */
export function nonDefault<T extends SomeSettings>(values: T): Partial<T> {
  const out: SomeSettings = {};
  for (const k of SETTING_NAMES) {
    const v = values[k];
    if (v !== undefined && v !== DEFAULTS[k]) put(out, k, v);
  }
  return out as Partial<T>;
}

export function parse(spec: SettingSpec, raw: string | boolean): { value?: Value; error?: string } {
  if (spec.kind === "bool") return { value: Boolean(raw) };
  if (spec.kind === "enum") {
    return spec.choices.includes(String(raw)) ? { value: String(raw) } : { error: `choose one of ${spec.choices.join(", ")}` };
  }
  if (spec.kind === "order") return parseOrder(spec.choices, String(raw));
  const text = String(raw).trim().replace(",", ".");
  if (text === "") return { error: "a value is needed" };
  const x = Number(text);
  if (!Number.isFinite(x)) return { error: `"${String(raw).trim()}" is not a number` };
  if (spec.kind === "integer" && !Number.isInteger(x)) return { error: "must be a whole number" };
  const unit = spec.unit ? ` ${spec.unit}` : "";
  if (spec.min !== null && (spec.min_exclusive ? x <= spec.min : x < spec.min)) {
    return { error: spec.min_exclusive ? `must be greater than ${spec.min}${unit}` : `must be at least ${spec.min}${unit}` };
  }
  if (spec.max !== null && x > spec.max) return { error: `must be at most ${spec.max}${unit}` };
  return { value: x };
}

/** An order of units (`unit_order`): one of `choices` (`unitN_first`, one per unit the core
 *  knows) or a list of different units such as "2, 0, 1", written as the core writes it
 *  (src/base/settings/units.rs `UnitOrder::word`): the whole order, the others following by
 *  number, and `unitN_first` where it is one. */
export function parseOrder(choices: readonly string[], raw: string): { value?: string; error?: string } {
  const text = raw.trim();
  if (choices.includes(text)) return { value: text };
  const all = choices.length;
  const list = text.split(",").map((t) => t.trim());
  const order = list.map((t) => (/^\+?[0-9]+$/.test(t) ? Number(t) : NaN));
  if (!order.every((u) => u < all) || new Set(order).size !== order.length) {
    return { error: `choose one of ${choices.join(", ")}, or list different units 0 … ${all - 1} such as 2,0,1` };
  }
  for (let u = 0; u < all; u++) if (!order.includes(u)) order.push(u);
  const first = order.slice(1).every((u, i, rest) => i === 0 || rest[i - 1] < u) ? `unit${order[0]}_first` : null;
  return { value: first !== null && choices.includes(first) ? first : order.join(",") };
}

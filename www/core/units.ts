// The machine's discharge units (docs/spec.md "Discharge units", as a list): how many there are (the setting
// `units`, 1 … 4; 2 when the settings have no `units`, as a core before that setting), each
// unit's settings (`unitN_<name>` for unit N ≥ 1, the plain name for unit 0), the unit that
// prints the support (`support = unitN`) and each unit's colours. Every view that shows
// something per unit loops over `unitIndices(n)`; nothing here touches the DOM.

import { DEFAULTS, MAX_UNITS, type SettingName, type UnitKey } from "./settings";

/** Most discharge units a machine has (the core's range of `units`, from its table). */
export { MAX_UNITS };
/** The units of a job whose settings do not say (today's machine: unit 0 and unit 1). */
export const DEFAULT_UNITS = DEFAULTS.units;

/** The number of units the settings give (`units`), else [[DEFAULT_UNITS]]; a value out of
 *  1 … [[MAX_UNITS]] (the core refuses it) counts as the default. */
export function unitsOf(settings: { readonly [name: string]: unknown } | null | undefined): number {
  const v = settings?.units;
  const n = typeof v === "string" && /^\d+$/.test(v.trim()) ? Number(v) : v;
  return typeof n === "number" && Number.isInteger(n) && n >= 1 && n <= MAX_UNITS ? n : DEFAULT_UNITS;
}

/** 0 … n − 1. */
export function unitIndices(n: number): number[] {
  return Array.from({ length: n }, (_, u) => u);
}

/** The unit N of a per-unit setting's name `unitN_<name>` (N ≥ 1; null: unit 0's or no unit's). */
export function unitOfSetting(name: string): number | null {
  const m = /^unit([1-9][0-9]*)_/.exec(name);
  return m ? Number(m[1]) : null;
}

/** The name of unit `u`'s own value of the setting `name` (unit 0's is the plain name). A
 *  setting of the table for u < [[MAX_UNITS]]; beyond, a name no setting has (nothing found
 *  under it: `isSettingName` tells). */
export function unitSetting(name: UnitKey, u: number): SettingName {
  return (u === 0 ? name : `unit${u}_${name}`) as SettingName;
}

/** `unitN_<name>` → `<name>` (any other name as it is). */
export function plainSetting(name: string): string {
  return unitOfSetting(name) === null ? name : name.replace(/^unit[0-9]+_/, "");
}

/** The unit that prints the support (`support = unitN`), null when `support` is off. */
export function supportUnit(support: unknown): number | null {
  const m = typeof support === "string" ? /^unit([1-9][0-9]*)$/.exec(support) : null;
  return m ? Number(m[1]) : null;
}

/** What unit u prints, in words (the parts panel's choice). */
export function unitRole(u: number): string {
  return ["main material", "second material", "third material", "fourth material"][u] ?? `material ${u + 1}`;
}

/** The droplets of unit u's parts in the layer view and the cut (unit 0's are coloured by
 *  their role instead; index 0 is its fill's blue, for a swatch), and the legends' swatches
 *  (style.css `i.unitN`). Units 0 and 1 keep the colours the page had with two units; units
 *  2 and 3 are dark so that they stand apart from the roles, the support and the overlays in
 *  lightness too (with colour vision deficiencies). */
export const UNIT_COLORS = ["#3b8fdd", "#7048e8", "#6b4226", "#343a40"] as const;
/** The per-layer plot's bars of unit u's parts (style.css `.plot-key i.barN`). */
export const UNIT_BARS = ["#a5c8ec", "#b9a7f4", "#cfae8e", "#9aa3ad"] as const;
/** Unit u's parts in the 3D view (lit, so a little lighter than the droplets' colours). */
export const UNIT_COLORS_3D = [0x7f9cc4, 0x7048e8, 0x8d5b34, 0x5c646c] as const;

/** Unit u's entry of a per-unit palette (the last one beyond it). */
export function unitColor<T>(palette: readonly T[], u: number): T {
  return palette[Math.max(0, Math.min(palette.length - 1, u))];
}

/** A layer's droplets of each unit's parts, the support left out (role 3; the core's roles
 *  partition the droplets): index u is unit u's, as many as the highest unit seen + 1 (at
 *  least 1). Counted from the per-droplet `roles` and `units` the core hands out with every
 *  layer, so it needs no per-unit figure of the core's. */
export function partsByUnit(roles: Uint8Array, units: Uint8Array): number[] {
  const out = [0];
  const n = Math.min(roles.length, units.length);
  for (let i = 0; i < n; i++) {
    if (roles[i] === 3) continue;
    const u = units[i];
    while (out.length <= u) out.push(0);
    out[u]++;
  }
  // droplets without a unit (a shorter `units`) are unit 0's
  for (let i = n; i < roles.length; i++) if (roles[i] !== 3) out[0]++;
  return out;
}

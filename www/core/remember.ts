// What the page remembers across reloads (local storage): the settings that differ from the
// defaults and the view (layer or 3D, the layer, the overlay toggles). Whatever is read back is
// checked like any input from outside: a setting must be one of the schema's, of its kind and
// in its range; anything else is dropped, and an entry that is not ours at all is ignored. No DOM.

import { jobSettings } from "./job";
import { nonDefault, parse, put, type Settings, type SomeSettings, type Spec } from "./settings";

/** The storage key (a new shape of entry gets a new key). */
export const REMEMBER_KEY = "dropslice.page.v1";
/** Longest entry read back (a real one is well under 4 KB). */
const TEXT_MAX = 64 * 1024;
/** Highest layer index remembered (any slice is clamped to its own layers later). */
const LAYER_MAX = 1_000_000;

export interface RememberedView {
  mode: "layer" | "3d";
  layer: number | null;
  travel: boolean;
  below: boolean;
  voids: boolean;
  overhangs: boolean;
}

export interface Remembered {
  /** Only settings that differ from the defaults. */
  settings: SomeSettings;
  view: RememberedView;
}

export const DEFAULT_VIEW: RememberedView = { mode: "layer", layer: null, travel: false, below: true, voids: false, overhangs: false };

const isObject = (v: unknown): v is Record<string, unknown> => typeof v === "object" && v !== null && !Array.isArray(v);

/** The settings of `raw` that the schema knows, of their kind and in range (part keys are not
 *  remembered: they belong to the parts). */
export function checkSettings(raw: unknown, schema: readonly Spec[]): SomeSettings {
  const out: SomeSettings = {};
  if (!isObject(raw)) return out;
  for (const spec of schema) {
    if (spec.part || !Object.hasOwn(raw, spec.name)) continue;
    const v = raw[spec.name];
    const ok = spec.kind === "bool" ? typeof v === "boolean" : spec.kind === "enum" || spec.kind === "order" ? typeof v === "string" : typeof v === "number" && Number.isFinite(v);
    if (!ok) continue;
    const r = parse(spec, v as string | boolean);
    if (r.value !== undefined && r.error === undefined) put(out, spec.name, r.value);
  }
  return out;
}

function checkView(raw: unknown): RememberedView {
  const view = { ...DEFAULT_VIEW };
  if (!isObject(raw)) return view;
  if (raw.mode === "layer" || raw.mode === "3d") view.mode = raw.mode;
  if (typeof raw.layer === "number" && Number.isInteger(raw.layer) && raw.layer >= 0 && raw.layer <= LAYER_MAX) view.layer = raw.layer;
  for (const k of ["travel", "below", "voids", "overhangs"] as const) if (typeof raw[k] === "boolean") view[k] = raw[k];
  return view;
}

/** The remembered state in `text` (null: none, or not an entry of this page). */
export function readRemembered(text: string | null, schema: readonly Spec[]): Remembered | null {
  if (text === null || text.length > TEXT_MAX) return null;
  let raw: unknown;
  try {
    raw = JSON.parse(text);
  } catch {
    return null;
  }
  if (!isObject(raw)) return null;
  return { settings: checkSettings(raw.settings, schema), view: checkView(raw.view) };
}

/** The entry to store: the settings that differ from the defaults (the part keys are the
 *  parts'), and the view. */
export function rememberedText(values: Settings, view: RememberedView): string {
  return JSON.stringify({ settings: nonDefault(jobSettings(values)), view });
}

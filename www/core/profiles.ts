// Profiles (docs/spec.md "Profiles"): named sets of settings of one kind, `{name, kind: "machine" |
// "material", settings}`, kept in the browser under one local-storage key. What is read back is
// checked entry by entry (a corrupt entry is dropped, the others kept); a file the user imports
// is checked by the core (`check_profile`, flows/profiles.ts) before it is added here.
//
// A material profile holds one material: its keys name no unit (`droplet_aspect`, …), and
// using it names the unit it is for (its keys become that unit's: `unit2_droplet_aspect`, …).
// A material profile saved before the units were a list holds both units' keys (`unit1_…`
// beside unit 0's): it is used as it is, its values where they went before.

import { checkSettings } from "./remember";
import { isSettingName, isUnitKey, put, type SettingName, type SomeSettings, type Spec } from "./settings";
import { plainSetting, unitOfSetting, unitSetting } from "./units";

export const PROFILES_KEY = "dropslice.profiles.v1";
/** Most profiles kept (each is a dozen settings at most). */
export const MAX_PROFILES = 200;
/** Longest name, in characters (the core's `MAX_PROFILE_NAME_CHARS`). */
export const MAX_NAME_CHARS = 100;
/** Largest profile file imported, bytes (the core's `MAX_PROFILE_BYTES`). */
export const MAX_PROFILE_BYTES = 64 << 10;

export type ProfileKind = "machine" | "material";

/** The settings a profile of `kind` holds: the core's schema flags them (`SettingSpec.profile`,
 *  from src/base/settings/profile.rs); the core refuses any other key when it checks one. */
export const profileKeys = (kind: ProfileKind, schema: readonly Spec[]): SettingName[] =>
  schema.filter((s) => s.profile === kind).map((s) => s.name);

export interface StoredProfile {
  name: string;
  kind: ProfileKind;
  settings: SomeSettings;
}

const isObject = (v: unknown): v is Record<string, unknown> => typeof v === "object" && v !== null && !Array.isArray(v);

/** Why `raw` is not a usable profile name (null: it is). */
/** Characters that show nothing, trimmed from a name's ends with the spaces: the core's set
 *  (`invisible` in src/base/settings/profile.rs), so a name is a name by one rule. */
const INVISIBLE = "\u00ad\u034f\u061c\u180e\u200b-\u200f\u202a-\u202e\u2060-\u2064\u2066-\u2069\ufeff";
const ENDS = new RegExp(`^[\\s${INVISIBLE}]+|[\\s${INVISIBLE}]+$`, "gu");

/** A name as the core keeps it: trimmed of spaces and invisible characters at its ends. */
export function trimName(raw: string): string {
  return raw.replace(ENDS, "");
}

export function nameProblem(raw: string): string | null {
  const name = trimName(raw);
  if (name === "" || [...name].length > MAX_NAME_CHARS) return `A profile's name must have 1 to ${MAX_NAME_CHARS} visible characters.`;
  // eslint-disable-next-line no-control-regex
  if (/[\u0000-\u001f\u007f-\u009f]/.test(name)) return "A profile's name must not hold line breaks or tabs.";
  return null;
}

/** Whether a profile of `kind` may hold `key`: a key of its kind's, or a unit's own name of
 *  one (`unitN_<key>`, a setting of the schema: an older material profile's `unit1_…`). */
function allowedKey(key: string, keys: readonly string[]): boolean {
  if (keys.includes(key)) return true;
  return unitOfSetting(key) !== null && keys.includes(plainSetting(key)) && isSettingName(key);
}

/** `raw` as a profile: every setting of its kind's, known to the schema and in range, none
 *  else (null: not a profile, or a value the schema refuses). */
export function checkProfile(raw: unknown, schema: readonly Spec[]): StoredProfile | null {
  if (!isObject(raw) || typeof raw.name !== "string" || nameProblem(raw.name) !== null) return null;
  if (raw.kind !== "machine" && raw.kind !== "material") return null;
  if (!isObject(raw.settings)) return null;
  const keys = profileKeys(raw.kind, schema);
  const given = Object.keys(raw.settings);
  if (given.some((k) => !allowedKey(k, keys))) return null;
  const settings = checkSettings(raw.settings, schema);
  if (Object.keys(settings).length !== given.length) return null;
  return { name: trimName(raw.name), kind: raw.kind, settings };
}

/** The profiles kept in `text` (the storage's entry): the good ones, names unique. */
export function readProfiles(text: string | null, schema: readonly Spec[]): StoredProfile[] {
  if (!text) return [];
  let raw: unknown;
  try {
    raw = JSON.parse(text);
  } catch {
    return [];
  }
  if (!Array.isArray(raw)) return [];
  const out: StoredProfile[] = [];
  for (const entry of raw.slice(0, MAX_PROFILES)) {
    const p = checkProfile(entry, schema);
    if (p && !out.some((q) => q.name === p.name)) out.push(p);
  }
  return out;
}

export const profilesText = (list: readonly StoredProfile[]): string => JSON.stringify(list);

/** A profile of `kind` with the current `values` of its settings: a material profile the
 *  material of `unit` (its values under names without a unit), a machine profile every unit's. */
export function profileOf(name: string, kind: ProfileKind, values: SomeSettings, schema: readonly Spec[], unit = 0): StoredProfile {
  const settings: SomeSettings = {};
  for (const k of profileKeys(kind, schema)) {
    if (kind === "material") {
      // a material setting a unit has (unit 0's name); unit N's own names are skipped
      if (!isUnitKey(k)) continue;
      const v = values[unitSetting(k, unit)];
      if (v !== undefined) put(settings, k, v);
    } else if (values[k] !== undefined) put(settings, k, values[k]);
  }
  return { name: trimName(name), kind, settings };
}

/** Whether using `p` names a unit: a material profile whose keys name none. */
export function needsUnit(p: StoredProfile): boolean {
  return p.kind === "material" && Object.keys(p.settings).every((k) => unitOfSetting(k) === null);
}

/** The settings `p` sets used for `unit` (a material profile of one material: its keys become
 *  that unit's), or as they are (a machine profile, an older material profile with `unit1_`
 *  keys); `missing`: keys the schema has not for that unit (a unit the core does not know). */
export function profileSettings(p: StoredProfile, unit: number): { settings: SomeSettings; missing: string[] } {
  if (!needsUnit(p)) return { settings: { ...p.settings }, missing: [] };
  const settings: SomeSettings = {};
  const missing: string[] = [];
  for (const [k, v] of Object.entries(p.settings)) {
    const name = isUnitKey(k) ? unitSetting(k, unit) : unit === 0 ? k : `unit${unit}_${k}`;
    if (isSettingName(name) && v !== undefined) put(settings, name, v);
    else missing.push(name);
  }
  return { settings, missing };
}

/** The file a profile is exported as (the JSON of docs/spec.md "Profiles"). */
export function profileFileText(p: StoredProfile): string {
  return JSON.stringify({ name: p.name, kind: p.kind, settings: p.settings }, null, 2) + "\n";
}

/** A file name for the profile: its name's letters and digits. */
export function profileFileName(p: StoredProfile): string {
  const base = p.name.replace(/[^\p{L}\p{N}._-]+/gu, "-").replace(/^-+|-+$/g, "").slice(0, 60);
  return `${base || "profile"}.${p.kind}.json`;
}

/** Why `p` cannot join `list` (null: it can): a new name when [[MAX_PROFILES]] are kept
 *  already (the list read back keeps only that many, so a 201st would be lost). Replacing a
 *  profile of the same name always fits. */
export function roomProblem(list: readonly StoredProfile[], p: StoredProfile): string | null {
  if (list.length < MAX_PROFILES || list.some((q) => q.name === p.name)) return null;
  return `There are ${MAX_PROFILES} profiles, the most the page keeps: delete one (export it first to keep it as a file), or save under the name of one to replace it.`;
}

/** `list` with `p` in it: a profile of the same name is replaced in place. */
export function withProfile(list: readonly StoredProfile[], p: StoredProfile): StoredProfile[] {
  const i = list.findIndex((q) => q.name === p.name);
  return i < 0 ? [...list, p] : list.map((q, j) => (j === i ? p : q));
}

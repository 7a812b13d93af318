// Profiles (core/profiles.ts keeps and checks them, views/profiles.ts draws them): save the
// current settings of a kind as a profile (a material: one unit's), use one (its settings into
// the form, one undoable change; a material for the unit the user picks), rename, delete,
// export a JSON file, import one (checked by the core first). The
// list lives in local storage; storage that is blocked or full gets a message, never an error.

import {
  MAX_PROFILE_BYTES,
  nameProblem,
  trimName,
  PROFILES_KEY,
  profileFileName,
  profileFileText,
  profileOf,
  profileSettings,
  profilesText,
  readProfiles,
  roomProblem,
  withProfile,
  needsUnit,
  type ProfileKind,
  type StoredProfile,
} from "../core/profiles";
import { isErrorValue } from "../core/protocol";
import { updateButtons } from "../views/controls";
import { saveFile } from "../views/download";
import type { Page } from "../views/page";
import { profileMessage, renderProfiles } from "../views/profiles";
import { unitsOf } from "../core/units";
import { record } from "./record";
import { relayout } from "./job";
import { saveSoon } from "./remember";

function load(page: Page): StoredProfile[] {
  try {
    return readProfiles(localStorage.getItem(PROFILES_KEY), page.init!.schema);
  } catch {
    return [];
  }
}

/** Stores `list` and draws it; false (with a message) when the storage refuses. */
function store(page: Page, list: StoredProfile[]): boolean {
  try {
    localStorage.setItem(PROFILES_KEY, profilesText(list));
  } catch {
    profileMessage("The browser refused to store the profiles (storage full or blocked); export them to keep them.", true);
    return false;
  }
  renderProfiles(page, list);
  return true;
}

/** Draws the stored profiles (at start). */
export function showProfiles(page: Page): void {
  renderProfiles(page, load(page));
}

/** Saves the settings of `kind` as `name`: a material profile the material of `unit`. */
export function saveProfile(page: Page, name: string, kind: ProfileKind, unit = 0): void {
  const form = page.form;
  if (!form) return;
  const problem = nameProblem(name);
  if (problem) return profileMessage(problem, true);
  if (form.errors().length) return profileMessage("Fix the settings marked in red first.", true);
  const p = profileOf(name, kind, form.values(), page.init!.schema, unit);
  const list = load(page);
  const full = roomProblem(list, p);
  if (full) return profileMessage(`“${p.name}” was not saved. ${full}`, true);
  const replaced = list.some((q) => q.name === p.name);
  const of = kind === "material" && unitsOf(form.values()) > 1 ? ` (the material of unit ${unit})` : "";
  if (store(page, withProfile(list, p))) profileMessage(`${replaced ? "Replaced" : "Saved"} the ${kind} profile “${p.name}”${of}.`);
}

/** The profile's settings into the form, one undoable change: a material profile of one
 *  material as unit `unit`'s (views/profiles.ts asks which), any other as it is. */
export function useProfile(page: Page, name: string, unit = 0): void {
  const p = load(page).find((q) => q.name === name);
  const form = page.form;
  if (!p || !form) return profileMessage(`There is no profile “${name}” any more.`, true);
  const { settings, missing } = profileSettings(p, unit);
  if (missing.length) return profileMessage(`The profile “${p.name}” was not used: this version has no ${missing.join(", ")}.`, true);
  const forUnit = needsUnit(p) ? ` for unit ${unit}` : "";
  form.set(settings);
  record(page, `use profile ${p.name}${forUnit}`, "settings");
  updateButtons(page);
  saveSoon(page);
  void relayout(page);
  profileMessage(`Using the ${p.kind} profile “${p.name}”${forUnit}.`);
}

export function renameProfile(page: Page, name: string, to: string): void {
  const problem = nameProblem(to);
  if (problem) return profileMessage(problem, true);
  const list = load(page);
  const target = trimName(to);
  if (target !== name && list.some((q) => q.name === target)) return profileMessage(`A profile “${target}” exists already: delete it first or pick another name.`, true);
  if (store(page, list.map((q) => (q.name === name ? { ...q, name: target } : q)))) profileMessage(`Renamed “${name}” to “${target}”.`);
}

export function deleteProfile(page: Page, name: string): void {
  if (store(page, load(page).filter((q) => q.name !== name))) profileMessage(`Deleted the profile “${name}” (the settings stay as they are).`);
}

export function exportProfile(page: Page, name: string): void {
  const p = load(page).find((q) => q.name === name);
  if (!p) return profileMessage(`There is no profile “${name}” any more.`, true);
  saveFile(new Blob([profileFileText(p)], { type: "application/json" }), profileFileName(p));
}

/** A profile file checked by the core, then added (it is not used until picked). */
export async function importProfile(page: Page, file: File): Promise<void> {
  const refuse = (why: string) => profileMessage(`${file.name} was not imported: ${why}`, true);
  if (file.size > MAX_PROFILE_BYTES) return refuse(`it has ${file.size} bytes; a profile file has at most ${MAX_PROFILE_BYTES}. Pick a profile's JSON file.`);
  // the bytes as they are: the core decodes them by the CLI's rule (src/base/settings/profile.rs)
  let bytes: Uint8Array;
  try {
    bytes = new Uint8Array(await file.arrayBuffer());
  } catch {
    return refuse("the browser could not read it.");
  }
  let checked: unknown;
  try {
    checked = await page.pool.checkProfile(bytes);
  } catch (e) {
    const detail = isErrorValue(e) ? e.message.replace(/\.$/, "") : String(e);
    return refuse(`${detail}. A profile is {"name": …, "kind": "machine" | "material", "settings": {…}}.`);
  }
  // what the core accepted, read back as the list keeps it
  const p = readProfiles(JSON.stringify([checked]), page.init!.schema)[0];
  if (!p) return refuse("its settings are not those of this page's version.");
  const list = load(page);
  const full = roomProblem(list, p);
  if (full) return refuse(full);
  const replaced = list.some((q) => q.name === p.name);
  if (store(page, withProfile(list, p))) profileMessage(`Imported the ${p.kind} profile “${p.name}”${replaced ? " (it replaced the one of that name)" : ""}; pick it to use it.`);
}

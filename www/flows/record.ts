// Every change of the build job and the settings recorded into `page.history` (core/history.ts
// keeps the snapshots) once it is made: a part edit once the core accepted it, a new job once it
// is the page's, a setting as it is typed (typing on in the same field amends the same entry).
// Undo and redo are flows/history.ts; what else follows a recorded change (the job kept in the
// browser, flows/persist.ts) is wired by main.ts through `whenRecorded`.

import { snapshotOf } from "../core/history";
import { SETTING_NAMES, type SettingName, type Settings } from "../core/settings";
import { updateButtons } from "../views/controls";
import { updateUndo } from "../views/notices";
import type { Page } from "../views/page";

/** Typing on in the same setting within this time amends its entry. */
const AMEND_MS = 1500;

/** The last settings entry: which settings it changed and when (to amend it). */
let lastSettings: { names: string; at: number } | null = null;
/** Set while the page itself sets the form (restore, reset): no entry of its own. */
let quiet = false;
/** What follows a recorded change (main.ts: the job kept in the browser). */
let recorded: (page: Page, label?: string) => void = () => {};

/** `then(page, label)` after every recorded change (one listener: main.ts wires persist). */
export function whenRecorded(then: (page: Page, label?: string) => void): void {
  recorded = then;
}

/** Sets the form by `set` without an entry of its own (undo, redo, reset). */
export function quietly(set: () => void): void {
  quiet = true;
  try {
    set();
  } finally {
    quiet = false;
  }
}

/** The next settings change starts an entry of its own (after an undo or a redo). */
export function endAmend(): void {
  lastSettings = null;
}

/** Records the state now as the result of the change `label`: `edit` (the job changed: leaving
 *  the page asks), `open` (a new job) or `settings`. */
export function record(page: Page, label: string, kind: "edit" | "open" | "settings" = "edit"): void {
  if (!page.form) return;
  if (kind !== "settings") lastSettings = null;
  page.history.commit(snapshotOf(page.store.job, page.form.values()), label);
  if (kind === "edit") page.store.edited = true;
  else if (kind === "open") page.store.edited = false;
  updateUndo(page);
  recorded(page, label);
}

/** The names of the settings that differ between `a` and `b`. */
function changedNames(a: Settings, b: Settings): SettingName[] {
  return SETTING_NAMES.filter((k) => a[k] !== b[k]);
}

/** A setting was changed in the form (called on every input): recorded, or amended while the
 *  same setting is typed on. */
export function settingsChanged(page: Page): void {
  const form = page.form;
  const before = page.history.present;
  if (quiet || !form || !before) return;
  const values = form.values();
  const names = changedNames(before.settings, values);
  if (names.length === 0) return;
  const key = names.join();
  const now = performance.now();
  if (lastSettings && lastSettings.names === key && now - lastSettings.at < AMEND_MS) {
    page.history.amend(snapshotOf(page.store.job, values));
    lastSettings.at = now;
    return;
  }
  record(page, names.length === 1 ? `change ${names[0].replace(/_/g, " ")}` : `change ${names.length} settings`, "settings");
  lastSettings = { names: key, at: now };
}

/** Every setting back to its default, as one undoable change. */
export function resetSettings(page: Page): void {
  const form = page.form;
  if (!form) return;
  quietly(() => form.reset());
  record(page, "reset settings to defaults", "settings");
  updateButtons(page);
}

// The profile manager in the settings panel: the saved profiles (use, rename, export, delete),
// "Save as profile" (a name and a kind: the current values of that kind's settings) and
// "Import…" (a JSON file). Each button is an action (flows/profiles.ts); the list is drawn from
// what the flow hands over.

import type { ProfileKind, StoredProfile } from "../core/profiles";
import { $ } from "./dom";
import type { Page } from "./page";

export function wireProfiles(page: Page): void {
  const { actions } = page;
  const name = $<HTMLInputElement>("profile-name");
  const save = () => actions.profileSave(name.value, $<HTMLSelectElement>("profile-kind").value as ProfileKind);
  $("profile-save").addEventListener("click", save);
  name.addEventListener("keydown", (ev) => {
    if (ev.key === "Enter") {
      ev.preventDefault();
      save();
    }
  });
  $("profile-import").addEventListener("click", () => $<HTMLInputElement>("profile-file").click());
  $<HTMLInputElement>("profile-file").addEventListener("change", (ev) => {
    const input = ev.target as HTMLInputElement;
    const file = input.files?.[0];
    input.value = "";
    if (file) actions.profileImport(file);
  });
}

function button(text: string, title: string, run: () => void, cls = "btn small"): HTMLButtonElement {
  const b = document.createElement("button");
  b.type = "button";
  b.className = cls;
  b.textContent = text;
  b.title = title;
  b.addEventListener("click", run);
  return b;
}

/** Draws the saved profiles. */
export function renderProfiles(page: Page, list: readonly StoredProfile[]): void {
  const { actions } = page;
  const items = list.map((p) => {
    const li = document.createElement("li");
    li.dataset.name = p.name;
    const keys = Object.keys(p.settings).join(", ");
    const use = button(`${p.name} (${p.kind})`, `Use this ${p.kind} profile: ${keys || "no settings"}`, () => actions.profileUse(p.name), "btn small profile-use");
    const rename = button("Rename", "Rename this profile", () => {
      const to = window.prompt(`New name of the profile “${p.name}”:`, p.name);
      if (to !== null) actions.profileRename(p.name, to);
    });
    const exp = button("Export", "Download this profile as a JSON file", () => actions.profileExport(p.name));
    const del = button("Delete", "Delete this profile (the settings stay as they are)", () => {
      if (window.confirm(`Delete the profile “${p.name}”?`)) actions.profileDelete(p.name);
    });
    rename.classList.add("profile-rename");
    exp.classList.add("profile-export");
    del.classList.add("profile-delete");
    li.append(use, rename, exp, del);
    return li;
  });
  $("profile-list").replaceChildren(...items);
}

/** A line under the profiles (`bad`: what went wrong and what to do). */
export function profileMessage(text: string, bad = false): void {
  const el = $("profile-status");
  el.textContent = text;
  el.classList.toggle("bad", bad);
}

// The profile manager in the settings panel: the saved profiles (use, rename, export, delete),
// "Save as profile" (a name and a kind: the current values of that kind's settings; a
// material: the unit's whose material it holds) and "Import…" (a JSON file). Using a material
// profile of one material asks which unit it is for: a button per unit of the machine (with
// one unit, it is unit 0's at once). Each button is an action (flows/profiles.ts); the list is
// drawn from what the flow hands over.

import { needsUnit, type ProfileKind, type StoredProfile } from "../core/profiles";
import { unitIndices, unitsOf } from "../core/units";
import { $, el } from "./dom";
import type { Page } from "./page";

/** The units of the machine (the form's `units`). */
const unitsNow = (page: Page): number => unitsOf(page.form?.values());

/** The save row's unit choice: shown for a material with more than one unit. */
function writeSaveUnit(page: Page): void {
  const n = unitsNow(page);
  const select = $<HTMLSelectElement>("profile-unit");
  const want = unitIndices(n).map(String);
  if ([...select.options].map((o) => o.value).join() !== want.join()) {
    const was = select.value;
    select.replaceChildren(...want.map((u) => new Option(`of unit ${u}`, u)));
    select.value = want.includes(was) ? was : "0";
  }
  select.hidden = n === 1 || $<HTMLSelectElement>("profile-kind").value !== "material";
}

export function wireProfiles(page: Page): void {
  const { actions } = page;
  const name = $<HTMLInputElement>("profile-name");
  const save = () => actions.profileSave(name.value, $<HTMLSelectElement>("profile-kind").value as ProfileKind, Number($<HTMLSelectElement>("profile-unit").value) || 0);
  $("profile-kind").addEventListener("change", () => writeSaveUnit(page));
  // the units may have changed since the list was drawn
  $("profiles").addEventListener("toggle", () => writeSaveUnit(page));
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
    const use = button(`${p.name} (${p.kind})`, `Use this ${p.kind} profile: ${keys || "no settings"}`, () => (needsUnit(p) && unitsNow(page) > 1 ? askUnit(page, li, p) : actions.profileUse(p.name, 0)), "btn small profile-use");
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
  writeSaveUnit(page);
}

/** Which unit a material profile of one material is for: a row of buttons under its line, one
 *  per unit (the first focused), and *Cancel*; a second click on the profile closes it. */
function askUnit(page: Page, li: HTMLElement, p: StoredProfile): void {
  const open = li.nextElementSibling?.classList.contains("profile-units");
  for (const row of $("profile-list").querySelectorAll(".profile-units")) row.remove();
  if (open) return;
  const close = () => {
    row.remove();
    li.querySelector<HTMLButtonElement>(".profile-use")?.focus();
  };
  const units = unitIndices(unitsNow(page)).map((u) => {
    const b = button(`Unit ${u}`, `Use “${p.name}” as the material of unit ${u}`, () => {
      row.remove();
      page.actions.profileUse(p.name, u);
    }, "btn small profile-unit");
    b.dataset.unit = String(u);
    return b;
  });
  const row = el("li", { class: "profile-units", role: "group", "aria-label": `Use “${p.name}” for which unit?` }, el("span", { class: "hint" }, "For unit:"), ...units, button("Cancel", "Use no profile", close));
  row.addEventListener("keydown", (ev) => {
    if (ev.key === "Escape") close();
  });
  li.after(row);
  units[0]?.focus();
}

/** A line under the profiles (`bad`: what went wrong and what to do). */
export function profileMessage(text: string, bad = false): void {
  const el = $("profile-status");
  el.textContent = text;
  el.classList.toggle("bad", bad);
}

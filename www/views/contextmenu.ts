// A part's context menu: right-click on a part in the 3D view (views/view3d/panel.ts) or on its
// line in the parts list (views/parts.ts), or the ContextMenu key / Shift+F10 on that line.
// Duplicate, Remove, Lay flat, Orient, Mirror X/Y/Z and Reset (rotation, scale and mirror back to
// the file's own), each through `page.actions`. A `role="menu"` of buttons: arrows, Home and End
// move, Enter or Space picks, Esc or Tab or a click elsewhere closes; the focus goes back to
// where it was (or to what `back` finds then: the list is drawn again after an edit).

import { MIRRORS, type Changes, type Part } from "../core/job";
import { DEFAULTS } from "../core/settings";
import { orientPart } from "./orient";
import type { Page } from "./page";

/** The change that turns the part's mirror along `axis` on or off. */
export function mirrorChange(p: Part, axis: "x" | "y" | "z"): Changes {
  const k = `mirror_${axis}` as const;
  return { [k]: !p.spec[k] };
}

/** The rotation, scale and mirror of the file itself (the part keys' defaults). */
const { rotate_x, rotate_y, rotate_z, scale_x, scale_y, scale_z } = DEFAULTS;
export const RESET = { rotate_x, rotate_y, rotate_z, scale_x, scale_y, scale_z, mirror_x: false, mirror_y: false, mirror_z: false } satisfies Changes;

/** Whether the part already has the file's own rotation, scale and mirror. */
function isReset(p: Part): boolean {
  return Object.entries(RESET).every(([k, v]) => p.spec[k as keyof typeof RESET] === v);
}

interface Item {
  id: string;
  label: string;
  disabled?: boolean;
  pressed?: boolean;
  run: () => void;
}

let menu: HTMLElement | null = null;
let openFor: number | null = null;
let returnTo: (() => HTMLElement | null) | null = null;

function element(): HTMLElement {
  if (menu) return menu;
  const m = document.createElement("div");
  m.id = "part-menu";
  m.className = "context-menu";
  m.setAttribute("role", "menu");
  m.hidden = true;
  m.addEventListener("keydown", onKey);
  m.addEventListener("focusout", (ev) => {
    // the focus left the menu (Tab, a click elsewhere): it closes, the focus stays there
    if (!m.contains(ev.relatedTarget as Node | null) && !m.hidden) closeMenu(false);
  });
  document.addEventListener(
    "pointerdown",
    (ev) => {
      if (!m.hidden && !m.contains(ev.target as Node)) closeMenu(false);
    },
    { capture: true },
  );
  document.body.append(m);
  menu = m;
  return m;
}

function buttons(): HTMLButtonElement[] {
  return [...element().querySelectorAll<HTMLButtonElement>("button:not(:disabled)")];
}

function onKey(ev: KeyboardEvent): void {
  const all = buttons();
  const at = all.indexOf(document.activeElement as HTMLButtonElement);
  const go = (i: number) => all[(i + all.length) % all.length]?.focus();
  if (ev.key === "ArrowDown") go(at + 1);
  else if (ev.key === "ArrowUp") go(at < 0 ? -1 : at - 1);
  else if (ev.key === "Home") go(0);
  else if (ev.key === "End") go(-1);
  else if (ev.key === "Escape") closeMenu(true);
  else if (ev.key === "Tab") {
    closeMenu(true);
  } else {
    // the menu has the keys while it has the focus: the page's own (Delete, the layer keys)
    // do not act behind it; Enter and Space press the item as usual
    ev.stopPropagation();
    return;
  }
  ev.preventDefault();
  ev.stopPropagation();
}

/** Closes the menu; `refocus`: the focus goes back to where the menu was opened from. */
export function closeMenu(refocus: boolean): void {
  const m = element();
  if (m.hidden) return;
  m.hidden = true;
  openFor = null;
  const back = returnTo;
  returnTo = null;
  if (refocus) back?.()?.focus({ preventScroll: true });
}

/** Whether the part menu is open (for the page's keys: Esc is the menu's then). */
export function menuOpen(): boolean {
  return menu !== null && !menu.hidden;
}

function items(page: Page, p: Part): Item[] {
  const { actions } = page;
  const job = page.store.job!;
  const edit = (changes: Changes) => void actions.editParts([{ id: p.id, changes }]);
  return [
    { id: "duplicate", label: "Duplicate", run: () => actions.duplicatePart(p.id) },
    { id: "remove", label: "Remove", disabled: job.parts.length <= 1, run: () => actions.removePart(p.id) },
    { id: "lay-flat", label: "Lay flat", run: () => actions.layFlat(p.id) },
    { id: "orient", label: "Orient…", run: () => void orientPart(page, p) },
    ...(["x", "y", "z"] as const).map((a, i) => ({ id: `mirror-${a}`, label: `Mirror ${a.toUpperCase()}`, pressed: p.spec[MIRRORS[i]], run: () => edit(mirrorChange(p, a)) })),
    { id: "reset", label: "Reset rotation, scale and mirror", disabled: isReset(p), run: () => edit(RESET) },
  ];
}

/** Opens part `id`'s menu at (x, y) (client px; kept within the window), the part selected.
 *  `back` finds what gets the focus when it closes. Opening it again for the same part while
 *  it is open does nothing (a key and its contextmenu event). */
export function openPartMenu(page: Page, id: number, x: number, y: number, back: () => HTMLElement | null): void {
  const job = page.store.job;
  const p = job?.part(id);
  if (!job || !p) return;
  if (openFor === id && menuOpen()) return;
  if (job.selected !== id) page.actions.selectPart(id);
  const m = element();
  m.setAttribute("aria-label", `Part ${job.parts.indexOf(p) + 1}`);
  m.replaceChildren(
    ...items(page, p).map((it) => {
      const b = document.createElement("button");
      b.type = "button";
      b.id = `part-menu-${it.id}`;
      b.setAttribute("role", it.pressed === undefined ? "menuitem" : "menuitemcheckbox");
      if (it.pressed !== undefined) b.setAttribute("aria-checked", String(it.pressed));
      b.tabIndex = -1;
      b.textContent = it.label;
      b.disabled = it.disabled === true;
      b.addEventListener("click", () => {
        closeMenu(true);
        it.run();
      });
      return b;
    }),
  );
  returnTo = back;
  openFor = id;
  m.hidden = false;
  // within the window
  const r = m.getBoundingClientRect();
  m.style.left = `${Math.max(4, Math.min(x, window.innerWidth - r.width - 4))}px`;
  m.style.top = `${Math.max(4, Math.min(y, window.innerHeight - r.height - 4))}px`;
  buttons()[0]?.focus();
}

/** The selected part's menu from the keyboard in the 3D view: at the middle of `where`. */
export function openSelectedPartMenu(page: Page, where: HTMLElement): void {
  const job = page.store.job;
  const p = job?.part(job.selected) ?? (job?.parts.length === 1 ? job.parts[0] : undefined);
  if (!p) return;
  const r = where.getBoundingClientRect();
  openPartMenu(page, p.id, r.left + r.width / 2, r.top + r.height / 2, () => where);
}

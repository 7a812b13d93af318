// The settings and the view remembered across reloads (core/remember.ts checks what is read
// back): read once at start (a preview link's settings then take precedence), written a moment
// after every change and when the page is left. Storage that is full, blocked or holds
// something else is ignored quietly: the page starts from the defaults.

import { readRemembered, rememberedText, REMEMBER_KEY, type Remembered } from "../core/remember";
import { setOverlay } from "../views/layer";
import type { Page } from "../views/page";

/** Changes settle this long before they are written. */
const SAVE_MS = 300;
let timer = 0;
/** Set while the page shows a preview link's settings: the visitor's own remembered settings
 *  are not overwritten by a stranger's until the visitor changes a setting. */
let heldForLink = false;

/** A preview link is being opened (or not, `held` false). */
export function holdForLink(held: boolean): void {
  heldForLink = held;
}

/** The visitor changed a setting: from now on the page's settings are theirs to remember. */
export function settingsTouched(): void {
  heldForLink = false;
}

/** What the page remembered (null: nothing usable). */
export function loadRemembered(page: Page): Remembered | null {
  try {
    return readRemembered(localStorage.getItem(REMEMBER_KEY), page.init!.schema);
  } catch {
    // storage blocked (privacy settings, a sandboxed frame): nothing remembered
    return null;
  }
}

/** The remembered settings into the form and the view's toggles and mode. */
export function applyRemembered(page: Page, r: Remembered): void {
  page.form!.set(r.settings);
  for (const k of ["travel", "below", "voids", "overhangs"] as const) setOverlay(k, r.view[k]);
  if (r.view.mode === "3d") page.view3d.setActive(true);
}

export function saveSoon(page: Page): void {
  clearTimeout(timer);
  timer = window.setTimeout(() => saveNow(page), SAVE_MS);
}

export function saveNow(page: Page): void {
  clearTimeout(timer);
  if (heldForLink) return;
  const { form, init, renderer, store } = page;
  if (!form || !init) return;
  const view = {
    mode: page.view3d.active ? ("3d" as const) : ("layer" as const),
    layer: store.slice ? store.current : null,
    travel: renderer.showTravel,
    below: renderer.showBelow,
    voids: renderer.showVoids,
    overhangs: renderer.showOverhangs,
  };
  try {
    localStorage.setItem(REMEMBER_KEY, rememberedText(form.values(), view));
  } catch {
    // storage full or blocked: the settings are simply not remembered
  }
}

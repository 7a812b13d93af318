// Short notices of the page: the Undo and Redo buttons (what they would undo in their titles),
// the notice after a change that replaced work ("… — Undo"), and the note of a page opened
// from a preview link (the settings that differ from the defaults: kept until its ✕, a list to
// read). Notices sit above the stage in the page's flow (they push the canvases down, never
// over a control); information goes by itself after [[NOTICE_MS]] (not while the pointer or the
// focus is on it), and every notice goes on its ✕; errors stay until then (banner.ts).

import { $ } from "./dom";
import type { Page } from "./page";

/** Information goes by itself after this long (ms). */
export const NOTICE_MS = 8_000;

const timers = new WeakMap<HTMLElement, number>();
const paused = new WeakSet<HTMLElement>();

/** `el` hidden after `ms` (again from the start while the pointer or the focus is on it, so
 *  that it is never taken away from under the user); `ms` null: it stays (a timer before is
 *  cleared). */
export function dismissAfter(el: HTMLElement, ms: number | null): void {
  clearTimeout(timers.get(el));
  timers.delete(el);
  if (ms === null) return;
  if (!paused.has(el)) {
    paused.add(el);
    const hold = () => clearTimeout(timers.get(el));
    const again = () => {
      if (timers.has(el) && !el.hidden && !el.matches(":hover") && !el.contains(document.activeElement)) arm(el, ms);
    };
    el.addEventListener("pointerenter", hold);
    el.addEventListener("focusin", hold);
    el.addEventListener("pointerleave", again);
    el.addEventListener("focusout", () => setTimeout(again, 0));
  }
  arm(el, ms);
}

function arm(el: HTMLElement, ms: number): void {
  clearTimeout(timers.get(el));
  timers.set(
    el,
    window.setTimeout(() => {
      timers.delete(el);
      el.hidden = true;
    }, ms),
  );
}

/** What the notice's button does. */
let noticeAction: "undo" | "redo" = "undo";

const capital = (s: string) => s.charAt(0).toUpperCase() + s.slice(1);

/** The Undo and Redo buttons from the history. */
export function updateUndo(page: Page): void {
  const h = page.history;
  const undo = $<HTMLButtonElement>("btn-undo");
  const redo = $<HTMLButtonElement>("btn-redo");
  undo.disabled = h.undoLabel === null;
  redo.disabled = h.redoLabel === null;
  undo.title = h.undoLabel === null ? "Nothing to undo" : `Undo ${h.undoLabel} (Ctrl+Z)`;
  redo.title = h.redoLabel === null ? "Nothing to redo" : `Redo ${h.redoLabel} (Ctrl+Shift+Z or Ctrl+Y)`;
}

/** A notice `text` with a button that undoes (or redoes) the change it speaks of. */
export function undoNotice(page: Page, text: string, action: "undo" | "redo" = "undo"): void {
  noticeAction = action;
  $("undo-text").textContent = text;
  $("undo-again").textContent = capital(action);
  $("undo-note").hidden = false;
  dismissAfter($("undo-note"), NOTICE_MS);
  updateUndo(page);
}

function hideNotice(): void {
  dismissAfter($("undo-note"), null);
  $("undo-note").hidden = true;
}

/** The note of a page opened from a preview link: `differing` lists the link's settings that
 *  differ from the defaults ("layer height 0.2 mm (default 0.25)"). */
export function linkFromNote(differing: string[]): void {
  $("link-from-text").textContent = differing.length
    ? `Settings that differ from the defaults: ${differing.join(", ")}.`
    : "Every setting is at its default.";
  $("link-from").hidden = false;
}

export function wireNotices(page: Page): void {
  $("btn-undo").addEventListener("click", () => page.actions.undo());
  $("btn-redo").addEventListener("click", () => page.actions.redo());
  $("undo-again").addEventListener("click", () => {
    hideNotice();
    if (noticeAction === "undo") page.actions.undo();
    else page.actions.redo();
  });
  $("undo-close").addEventListener("click", hideNotice);
  $("link-from-close").addEventListener("click", () => ($("link-from").hidden = true));
  updateUndo(page);
}

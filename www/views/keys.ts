// The page's editing keys: Ctrl+Z undo, Ctrl+Shift+Z and Ctrl+Y redo (⌘ on a Mac), Delete or
// Backspace removes the selected part. None of them acts while the user types in a field (the
// field's own undo and deletion work there) or while a dialog is open.

import type { Page } from "./page";

/** Whether `t` takes typing: a text field, a list, an editable element. */
export function typingIn(t: EventTarget | null): boolean {
  if (!(t instanceof HTMLElement)) return false;
  if (t.isContentEditable || t instanceof HTMLTextAreaElement || t instanceof HTMLSelectElement) return true;
  if (t instanceof HTMLInputElement) return !["checkbox", "radio", "button", "submit", "reset", "range", "file", "color"].includes(t.type);
  return false;
}

export function wireKeys(page: Page): void {
  document.addEventListener("keydown", (ev) => {
    if (ev.defaultPrevented || typingIn(ev.target) || document.querySelector("dialog[open]")) return;
    const mod = ev.ctrlKey || ev.metaKey;
    const key = ev.key.toLowerCase();
    if (mod && !ev.altKey && key === "z") page.actions[ev.shiftKey ? "redo" : "undo"]();
    else if (mod && !ev.altKey && !ev.shiftKey && key === "y") page.actions.redo();
    else if (!mod && !ev.altKey && (ev.key === "Delete" || ev.key === "Backspace")) {
      const job = page.store.job;
      if (!job || job.selected === null) return;
      page.actions.removePart(job.selected);
    } else return;
    ev.preventDefault();
  });
}

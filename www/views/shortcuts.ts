// The keyboard shortcuts panel: every key the page answers, opened by "?" (outside a text
// field) or the *Keyboard shortcuts* button; Esc or *Close* closes it and the focus goes back
// to where it was. The keys themselves are wired where they act (views/layer.ts: layers and
// fit; main.ts: Enter slices, undo and redo, Delete; views/parts.ts, views/cut.ts: Enter in
// their fields; views/contextmenu.ts: a part's menu; views/dom.ts: the skip links).

import { $ } from "./dom";

/** [keys, what they do] by where they work. */
export const SHORTCUTS: { title: string; keys: [string, string][] }[] = [
  {
    title: "Layers (outside a text field)",
    keys: [
      ["→ or ↑", "Layer above"],
      ["← or ↓", "Layer below"],
      ["Page Up / Page Down", "10 layers up / down"],
      ["Home / End", "First / last layer"],
      ["F", "Fit the part to the view (3D: frame the plate)"],
    ],
  },
  {
    title: "The job",
    keys: [
      ["Ctrl+Z", "Undo the last change of the parts or the settings"],
      ["Ctrl+Shift+Z or Ctrl+Y", "Redo"],
      ["Delete", "Remove the selected part"],
      ["Enter (in the settings)", "Slice"],
      ["Enter or Space (on a part in the list)", "Select the part"],
      ["Menu key or Shift+F10 (on a part in the list; in 3D: the selected part)", "The part's menu: duplicate, remove, lay flat, orient, mirror, reset"],
      ["↑ / ↓, Enter, Esc (in a part's menu)", "Move, pick, close (the focus goes back)"],
      ["Enter (in a part's field)", "Apply the value"],
      ["Enter (in the cut's position)", "Set the cut there"],
    ],
  },
  {
    title: "The page",
    keys: [
      ["Tab / Shift+Tab", "Next / previous control (the per-layer plot too: its arrows move the layer)"],
      ["Tab, Enter (from the page's top)", "Skip to Slice; Tab twice: skip to the layer view"],
      ["?", "This list"],
      ["Esc", "Close this list or a dialog"],
    ],
  },
  {
    title: "Mouse, on the layer view and the cut",
    keys: [
      ["Wheel", "Zoom about the pointer"],
      ["Drag", "Pan (3D: orbit; right-drag: pan)"],
      ["Double-click", "Fit"],
      ["Right-click (on a part in the list or in 3D)", "The part's menu"],
    ],
  },
];

/** Whether a key press goes to a field that takes text (where "?" is a character). */
function typing(t: EventTarget | null): boolean {
  if (!(t instanceof HTMLElement)) return false;
  if (t.isContentEditable || t instanceof HTMLTextAreaElement || t instanceof HTMLSelectElement) return true;
  return t instanceof HTMLInputElement && !["checkbox", "radio", "button", "range", "submit", "reset", "file"].includes(t.type);
}

function fill(list: HTMLElement): void {
  list.replaceChildren(
    ...SHORTCUTS.map((group) => {
      const section = document.createElement("section");
      const h = document.createElement("h4");
      h.textContent = group.title;
      const dl = document.createElement("dl");
      for (const [keys, what] of group.keys) {
        const dt = document.createElement("dt");
        const kbd = document.createElement("kbd");
        kbd.textContent = keys;
        dt.append(kbd);
        const dd = document.createElement("dd");
        dd.textContent = what;
        dl.append(dt, dd);
      }
      section.append(h, dl);
      return section;
    }),
  );
}

/** The panel, its button and the "?" key. */
export function wireShortcuts(): void {
  const dialog = $<HTMLDialogElement>("shortcuts-dialog");
  let back: HTMLElement | null = null;
  const open = () => {
    if (dialog.open) return;
    if (!dialog.dataset.filled) {
      fill($("shortcut-list"));
      dialog.dataset.filled = "1";
    }
    back = document.activeElement instanceof HTMLElement ? document.activeElement : null;
    dialog.showModal();
    $("shortcuts-close").focus();
  };
  $("btn-shortcuts").addEventListener("click", open);
  $("shortcuts-close").addEventListener("click", () => dialog.close());
  // Esc closes a modal dialog by itself; focus goes back to where it was in either case
  dialog.addEventListener("close", () => {
    back?.focus();
    back = null;
  });
  document.addEventListener("keydown", (ev) => {
    if (ev.key !== "?" || ev.ctrlKey || ev.metaKey || ev.altKey || typing(ev.target)) return;
    if (document.querySelector("dialog[open]")) return;
    ev.preventDefault();
    open();
  });
}

// Small DOM helpers of the views.

export const $ = <T extends HTMLElement = HTMLElement>(id: string) => document.getElementById(id) as T;

/** Sets an element's text; an unchanged text is left alone (no layout for nothing). */
export function setText(id: string, text: string): void {
  const e = $(id);
  if (e.textContent !== text) e.textContent = text;
}

export const nf = new Intl.NumberFormat("en-US");

/** A duration for people: "2 h 10 min", "3 min 5 s", "40 s". */
export function duration(seconds: number): string {
  if (!Number.isFinite(seconds)) return "–";
  const whole = Math.round(seconds);
  const h = Math.floor(whole / 3600);
  const m = Math.floor((whole % 3600) / 60);
  const s = whole % 60;
  if (h > 0) return `${h} h ${m} min`;
  if (m > 0) return `${m} min ${s} s`;
  return `${s} s`;
}

/** The skip links (the page's first focusable elements): "Skip to Slice" and "Skip to the layer
 *  view" move the focus there (the page's own move: a fragment alone would only scroll). A
 *  Slice button still disabled (no model yet) gives the focus to its row; a layer canvas hidden
 *  (the 3D tab) to the layer slider. */
export function wireSkipLinks(): void {
  const go = (ev: Event, el: HTMLElement) => {
    ev.preventDefault();
    el.scrollIntoView({ block: "nearest" });
    el.focus({ preventScroll: true });
  };
  $("skip-slice").addEventListener("click", (ev) => {
    const slice = $<HTMLButtonElement>("btn-slice");
    const row = slice.parentElement!;
    if (slice.disabled) row.tabIndex = -1;
    go(ev, slice.disabled ? row : slice);
  });
  $("skip-layer").addEventListener("click", (ev) => {
    const view = $("view");
    go(ev, view.getClientRects().length > 0 ? view : $("layer"));
  });
}

/** An element `tag` with attributes (`class`, `id`, `title`, `hidden`: "" …) and children. */
export function el(tag: string, attrs: Record<string, string | undefined>, ...children: (Node | string)[]): HTMLElement {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs)) if (v !== undefined) e.setAttribute(k, v);
  e.append(...children);
  return e;
}

/** The elements of units 1 … n − 1 (`make(u)`, in order) right after `anchor` (`before`: before it), each marked
 *  `data-units-of = key`; made again only when n changes (the views call this on every
 *  redraw). Unit 0's rows are the page's own markup. */
export function unitRows(key: string, anchor: Element, n: number, make: (u: number) => Element[], before = false): void {
  const parent = anchor.parentElement!;
  if (parent.dataset[`units${key}`] === String(n)) return;
  parent.dataset[`units${key}`] = String(n);
  for (const old of parent.querySelectorAll(`[data-units-of="${key}"]`)) old.remove();
  const made: Element[] = [];
  for (let u = 1; u < n; u++) made.push(...make(u));
  for (const e of made) e.setAttribute("data-units-of", key);
  if (before) anchor.before(...made);
  else anchor.after(...made);
}

/** "₁" for 1: a unit's droplet width B₁, B₂, … */
export const sub = (u: number): string => String(u).replace(/[0-9]/g, (d) => String.fromCharCode(0x2080 + Number(d)));

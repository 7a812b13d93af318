// Small DOM helpers of the views.

export const $ = <T extends HTMLElement = HTMLElement>(id: string) => document.getElementById(id) as T;

/** Sets an element's text; an unchanged text is left alone (no layout for nothing). */
export function setText(id: string, text: string): void {
  const e = $(id);
  if (e.textContent !== text) e.textContent = text;
}

export const nf = new Intl.NumberFormat("en-US");

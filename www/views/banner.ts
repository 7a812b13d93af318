// Messages: the banner (errors, notices) and the note about a preview link. Above the stage in
// the page's flow (never over a control); an error stays until its ✕, information goes by
// itself (notices.ts `dismissAfter`); the note goes on a click.

import { SliceError } from "../core/client";
import { plainJobMessage } from "../core/plate";
import { $ } from "./dom";
import { NOTICE_MS, dismissAfter } from "./notices";

export const TITLES: Record<string, string> = {
  import: "",
  setting: "Bad setting.",
  nothing_to_print: "Nothing to print.",
  crash: "The slicer crashed.",
  internal: "Internal error.",
  analysis: "The voids cannot be analysed.",
  link: "Cannot open this preview link.",
  linkPart: "Parts of this preview link were ignored.",
  job: "Cannot lay out this job.",
  jobFiles: "The job file needs its models.",
  linkFiles: "The preview link needs its models.",
};

/** Most characters of a banner's message: a message quoting a hostile file stays short (the
 *  core bounds its own messages too; this holds for every source). */
export const BANNER_MAX_CHARS = 600;

/** `message` cut to [[BANNER_MAX_CHARS]] (then "…"). */
export function clampMessage(message: string): string {
  return message.length > BANNER_MAX_CHARS ? `${message.slice(0, BANNER_MAX_CHARS)}…` : message;
}

/** Shows the banner; it stays until its ✕ when `stay` (an error, or information the page waits
 *  on: files still missing), else it goes by itself (notices.ts `dismissAfter`). */
export function showBanner(title: string, message: string, tone: "error" | "info" | "ok" = "error", stay = tone === "error"): void {
  message = clampMessage(message);
  const b = $("banner");
  b.className = `banner ${tone === "error" ? "" : tone}`;
  $("banner-title").textContent = title;
  $("banner-title").hidden = title === "";
  $("banner-message").textContent = message;
  b.hidden = false;
  b.dataset.kind = tone;
  dismissAfter(b, stay ? null : NOTICE_MS);
}

export function hideBanner(): void {
  dismissAfter($("banner"), null);
  $("banner").hidden = true;
}

/** The banner of an error: the core's kind of error as its title. */
export function errorBanner(e: unknown): void {
  if (e instanceof SliceError) {
    showBanner(TITLES[e.kind] ?? "Error.", capitalize(e.kind === "job" ? plainJobMessage(e.message) : e.message));
  } else if (e instanceof Error) {
    showBanner("Something went wrong.", e.message);
  } else {
    showBanner("Something went wrong.", String(e));
  }
}

function capitalize(s: string): string {
  return s.charAt(0).toUpperCase() + s.slice(1);
}

export function note(text: string, tone: "warn" | "ok" | "none"): void {
  const n = $("link-note");
  n.hidden = tone === "none";
  n.textContent = text;
  n.className = tone === "ok" ? "banner ok" : "note";
  n.title = tone === "none" ? "" : "Click to dismiss";
  dismissAfter(n, tone === "ok" ? NOTICE_MS : null);
  if (!n.dataset.wired) {
    n.dataset.wired = "1";
    n.addEventListener("click", () => (n.hidden = true));
  }
}

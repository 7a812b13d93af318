// Opening what the user gives the page: a file (STL or .gco), the sample part, or the preview
// link in the URL. Each ends in a flow of flows.ts.

import type { Value } from "./form";
import { openGcode, startSlice, type Target } from "./flows";
import type { Page } from "./page";
import { sampleStl } from "./sample";
import { LinkError, readLink, type SharedLink } from "./share";
import type { Model } from "./store";
import { note, showBanner, TITLES } from "./views/banner";
import { updateButtons } from "./views/controls";
import { nf } from "./views/dom";
import { setShowTravel } from "./views/layer";
import { showModel } from "./views/stats";
import { setState } from "./views/status";

export async function openFile(page: Page, file: File): Promise<void> {
  const store = page.store;
  const chosen = performance.now();
  setState("reading");
  if (/\.(gco|gcode)$/i.test(file.name)) {
    store.pendingLink = null;
    note("", "none");
    await openGcode(page, file);
    return;
  }
  // The File goes to a worker, which reads it and computes its SHA-256: the page never reads it.
  const m: Model = { file, name: file.name, sha256: "" };
  store.fileChosenAt = chosen;
  const link = store.pendingLink;
  if (link) {
    store.pendingLink = null;
    let sha256: string;
    try {
      sha256 = await page.pool.hash(file);
    } catch (e) {
      showBanner(TITLES.import, `The browser could not read “${file.name}”: ${e instanceof Error ? e.message : String(e)}`);
      return;
    }
    m.sha256 = sha256;
    if (link.state.sha256 === m.sha256) {
      note(`“${m.name}” matches the model of the preview link.`, "ok");
      await startSlice(page, m, { layer: link.state.layer, view: link.state.view });
      return;
    }
    note(
      `“${m.name}” does not match the model of the preview link (“${link.state.name}”, SHA-256 ${link.state.sha256.slice(0, 12)}…): this is a different file. It is sliced with the link's settings.`,
      "warn",
    );
  } else {
    note("", "none");
  }
  await startSlice(page, m);
}

/** A model from bytes the page already holds (the sample, a link's model), as a File for
 *  the workers. */
function modelOf(bytes: Uint8Array, name: string): Model {
  return { file: new File([bytes as BlobPart], name, { type: "model/stl" }), name, sha256: "" };
}

export async function openSample(page: Page, notice?: Target["notice"]): Promise<void> {
  const s = sampleStl();
  const m = modelOf(s.bytes, s.name);
  page.store.pendingLink = null;
  note("", "none");
  await startSlice(page, m, { notice });
}

/** What a link's settings must be for each kind of setting (the form checks the ranges). */
const KIND_TYPE: Record<string, { type: string; words: string }> = {
  number: { type: "number", words: "a number" },
  integer: { type: "number", words: "a whole number" },
  bool: { type: "boolean", words: "yes or no (true/false)" },
  enum: { type: "string", words: "one of the choices" },
};

/** The link's settings whose type fits their kind; the others named in `ignored`. Unknown
 *  names are kept (the form ignores them and the page says so). */
function linkSettings(page: Page, settings: Record<string, Value>, ignored: string[]): Record<string, Value> {
  const out: Record<string, Value> = {};
  for (const [name, v] of Object.entries(settings)) {
    const spec = page.init!.schema.find((x) => x.name === name);
    const want = spec ? KIND_TYPE[spec.kind] : undefined;
    if (want && typeof v !== want.type) {
      const shown = typeof v === "string" ? JSON.stringify(v.length > 24 ? `${v.slice(0, 24)}…` : v) : String(v);
      ignored.push(`its setting ${name} (${shown} is not ${want.words}: the default is used)`);
      continue;
    }
    out[name] = v;
  }
  return out;
}

/** Opens the preview link in the URL, if there is one (returns whether there was one that the
 *  page now shows or waits for a file of). A link too large or damaged is refused with a
 *  message and the sample part is shown; fields it gets wrong are ignored and named. */
export async function openLink(page: Page): Promise<boolean> {
  let link: SharedLink | null;
  try {
    link = await readLink(location.hash);
  } catch (e) {
    const why = e instanceof LinkError ? e.message : `it could not be read (${e instanceof Error ? e.message : String(e)})`;
    await openSample(page, { title: TITLES.link, message: `This preview link is too large or damaged: ${why}. Showing the sample part instead.` });
    return true;
  }
  if (!link) return false;
  const ignored = [...link.ignored];
  const unknown = page.form!.set({ ...page.init!.defaults, ...linkSettings(page, link.state.settings, ignored) });
  const extra = unknown.length
    ? ` The link comes from another version: its settings ${unknown.join(", ")} are unknown here and were ignored, so the slice may differ.`
    : "";
  if (extra) note(extra.trim(), "warn");
  setShowTravel(page, Boolean(link.state.showTravel));
  const notice: Target["notice"] = ignored.length
    ? { title: TITLES.linkPart, message: `This preview link is partly damaged: ${ignored.join("; ")}.`, tone: "info" }
    : undefined;
  const { layer, view, name, sha256 } = link.state;
  if (link.model) {
    const m = modelOf(link.model, name);
    m.sha256 = await page.pool.hash(m.file);
    if (m.sha256 === sha256) {
      await startSlice(page, m, { layer, view, notice });
      return true;
    }
    link.model = null;
    link.modelError = "its model does not match the SHA-256 it carries";
  }
  page.store.pendingLink = link;
  showModel(null);
  const at = layer !== undefined ? ` to see layer ${nf.format(layer + 1)}` : "";
  if (link.modelError) {
    const also = ignored.length ? ` Also ignored: ${ignored.join("; ")}.` : "";
    showBanner(TITLES.link, `This preview link is too large or damaged: ${link.modelError}. Its settings are applied; drop “${name}” here to see the slice.${also}`);
  } else if (notice) {
    showBanner(notice.title, notice.message, notice.tone);
  }
  note(
    link.modelError
      ? `The model “${name}” (SHA-256 ${sha256.slice(0, 12)}…) could not be taken from the link. Drop that file here${at} with the link's settings.${extra}`
      : `This preview link is for “${name}” (SHA-256 ${sha256.slice(0, 12)}…), which was too big to put in the link. Drop that file here${at} with the link's settings.${extra}`,
    "warn",
  );
  setState("idle");
  updateButtons(page);
  return true;
}

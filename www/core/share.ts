// Preview links: settings, layer, view, the build job and its models in the URL fragment (never
// sent to a server). The models are embedded together (their bytes one after the other,
// deflate-raw, base64url) when they compress to at most 256 KB in all; otherwise the link
// carries each file's SHA-256 and name, and the receiver drops in the same files, which the
// page matches by their hashes. A link of one model without a job (older pages) still opens.
//
// A link comes from anyone, so reading one is bounded: the encoded texts are measured before
// they are decoded, both parts are inflated as a stream that is cancelled as soon as it grows
// past its cap, and every field of the state is checked (type, finite, range) before the page
// uses it. Fields that are wrong are dropped and named (`ignored`); a link that is too large or
// damaged is refused with a [[LinkError]]. A job's parts are checked against the core's own
// ranges (its `job_schema`, which the page has from init).

import { checkLine, type Line } from "./cutline";
import { fitsPart, partNumber } from "./job";
import type { JobSchema, PartSpec } from "./protocol";
import type { RawSettings, Value } from "./settings";
import { MAX_CENTRE_MM, MAX_SCALE, MIN_SCALE, type View } from "./view";

export const EMBED_LIMIT = 256 * 1024;

/** The link's state (settings, layer, view, names) inflates to at most 64 KB: a state made
 *  here is well under 2 KB. */
export const STATE_MAX_BYTES = 64 * 1024;
/** An embedded model inflates to at most 64 MB. Links made here embed at most
 *  [[EMBED_LIMIT]] (256 KB) of deflated STL, which real STL files never inflate beyond a few
 *  MB; anything bigger is a deflate bomb (deflate can expand about 1000 times). */
export const MODEL_MAX_BYTES = 64 * 1024 * 1024;
const nf = new Intl.NumberFormat("en-US");

/** Base64 text of `n` bytes. */
const base64Chars = (n: number) => Math.ceil((n * 4) / 3);
/** Encoded lengths checked before decoding: the state's deflated bytes (incompressible data
 *  grows by a few bytes per block) and the model's, with room for 4 × [[EMBED_LIMIT]]. */
export const STATE_TEXT_MAX = base64Chars(STATE_MAX_BYTES + 1024);
export const MODEL_TEXT_MAX = base64Chars(4 * EMBED_LIMIT);
/** Bounds of the state's strings and settings. */
const NAME_MAX = 255;
const SETTING_TEXT_MAX = 100;
const SETTINGS_MAX = 500;
/** Compressed bytes handed to the inflater at a time: it is checked between pieces, so a bomb
 *  overshoots the cap by at most about 1000 × this (4 MB). */
const FEED_BYTES = 4096;

export interface ShareState {
  /** Settings that differ from the defaults (from outside: any names; the page checks each
   *  against the core's schema, flows/open.ts). */
  settings: RawSettings;
  /** Absent when the link's layer was unusable. */
  layer?: number;
  /** Absent when the link's view was unusable (the part is then fitted). */
  view?: View;
  /** The first model's name and SHA-256 (the only ones in a link of one model). */
  name: string;
  sha256: string;
  showTravel?: boolean;
  /** The stage shown: the layer view (with the cut when `cut` is set) or the 3D view. */
  mode?: "layer" | "3d";
  /** The 3D view's camera (plate mm). */
  camera?: LinkCamera;
  /** The vertical cut's line (plate mm). */
  cut?: Line;
  /** The layer view's overlays. */
  overlays?: Overlays;
  /** The job's files in the order their bytes are embedded: name (as the parts name it),
   *  SHA-256 and size. Absent in a link of one model without a job. */
  files?: LinkFile[];
  /** The job's parts (their `file` names one of `files`). */
  parts?: PartSpec[];
}

export interface LinkCamera {
  position: [number, number, number];
  target: [number, number, number];
}

export interface Overlays {
  below?: boolean;
  voids?: boolean;
  overhangs?: boolean;
}

/** The farthest a link's camera may be from the origin (mm): a plate is at most 100 m. */
const CAMERA_MAX_MM = 1e6;

export interface LinkFile {
  name: string;
  sha256: string;
  bytes: number;
}

export interface SharedLink {
  state: ShareState;
  /** The embedded bytes (every model, one after the other), when there were any. */
  model: Uint8Array | null;
  /** The embedded models, one per file of `state.files` (or the one model of an older link). */
  models: Uint8Array[] | null;
  /** Why an embedded model was refused (too large or damaged): the state is still usable. */
  modelError?: string;
  /** Parts of the state that were dropped or limited, in words ("its view (…)"). */
  ignored: string[];
}

/** A link too large or damaged to be read; the message says which part and why. */
export class LinkError extends Error {}

async function pipe(bytes: Uint8Array, stream: CompressionStream | DecompressionStream): Promise<Uint8Array> {
  const out = new Blob([bytes as BlobPart]).stream().pipeThrough(stream);
  return new Uint8Array(await new Response(out).arrayBuffer());
}

export const deflate = (b: Uint8Array) => pipe(b, new CompressionStream("deflate-raw"));

function size(bytes: number): string {
  return bytes >= 2 ** 20 ? `${bytes / 2 ** 20} MB` : `${bytes / 1024} KB`;
}

/**
 * Inflates `bytes` (deflate-raw), at most `cap` bytes: the input is fed in small pieces and
 * the output read as it comes; past the cap both sides are cancelled and a [[LinkError]]
 * naming `what` is thrown, as for data that is not valid deflate.
 */
export async function inflate(bytes: Uint8Array, cap = Infinity, what = "the data"): Promise<Uint8Array> {
  const ds = new DecompressionStream("deflate-raw");
  const writer = ds.writable.getWriter();
  const reader = ds.readable.getReader();
  const feeding = (async () => {
    for (let i = 0; i < bytes.length; i += FEED_BYTES) {
      await writer.write(bytes.slice(i, i + FEED_BYTES));
    }
    await writer.close();
  })();
  // a failure of the writing side shows up on the reading side too
  feeding.catch(() => {});
  const chunks: Uint8Array[] = [];
  let total = 0;
  try {
    for (;;) {
      const { value, done } = await reader.read();
      if (done) break;
      total += value.byteLength;
      if (total > cap) throw new LinkError(`${what} unpacks to more than ${size(cap)}, the most this page accepts`);
      chunks.push(value);
    }
    await feeding;
  } catch (e) {
    reader.cancel().catch(() => {});
    writer.abort().catch(() => {});
    if (e instanceof LinkError) throw e;
    throw new LinkError(`${what} is not valid compressed data (the link may have been cut short)`);
  }
  const out = new Uint8Array(total);
  let at = 0;
  for (const c of chunks) {
    out.set(c, at);
    at += c.byteLength;
  }
  return out;
}

export function toBase64Url(bytes: Uint8Array): string {
  let bin = "";
  const chunk = 0x8000;
  for (let i = 0; i < bytes.length; i += chunk) {
    bin += String.fromCharCode(...bytes.subarray(i, i + chunk));
  }
  return btoa(bin).replace(/\+/g, "-").replace(/\//g, "_").replace(/=+$/, "");
}

/** Decodes base64url of at most `max` characters; a [[LinkError]] naming `what` otherwise. */
export function fromBase64Url(text: string, max = Infinity, what = "the data"): Uint8Array {
  if (text.length > max) {
    throw new LinkError(`${what} is ${nf.format(text.length)} characters long; at most ${nf.format(max)} are accepted`);
  }
  if (!/^[A-Za-z0-9_-]*={0,2}$/.test(text) || text.length % 4 === 1) {
    throw new LinkError(`${what} holds characters that do not belong in a link (it may have been cut or changed)`);
  }
  const b64 = text.replace(/=+$/, "").replace(/-/g, "+").replace(/_/g, "/");
  let bin: string;
  try {
    bin = atob(b64 + "===".slice((b64.length + 3) % 4));
  } catch {
    throw new LinkError(`${what} is not valid base64 (it may have been cut or changed)`);
  }
  const out = new Uint8Array(bin.length);
  for (let i = 0; i < bin.length; i++) out[i] = bin.charCodeAt(i);
  return out;
}

export async function sha256Hex(bytes: Uint8Array): Promise<string> {
  const digest = await crypto.subtle.digest("SHA-256", bytes as BufferSource);
  return [...new Uint8Array(digest)].map((b) => b.toString(16).padStart(2, "0")).join("");
}

/** Builds the link; `embedded` tells whether the models travel inside it. The models are Blobs
 *  (the Files the user gave), in the order of `state.files`: compressed together as a stream,
 *  never read whole here. */
export async function makeLink(base: string, state: ShareState, models: Blob | Blob[]): Promise<{ url: string; embedded: boolean }> {
  const p = toBase64Url(await deflate(new TextEncoder().encode(JSON.stringify(state))));
  const all = new Blob(Array.isArray(models) ? models : [models]);
  const packed = new Uint8Array(await new Response(all.stream().pipeThrough(new CompressionStream("deflate-raw"))).arrayBuffer());
  const embedded = packed.length <= EMBED_LIMIT;
  const url = `${base.split("#")[0]}#p=${p}${embedded ? `&m=${toBase64Url(packed)}` : ""}`;
  return { url, embedded };
}

/** A value of the link as words for a message: short, whatever it is. */
function shown(v: unknown): string {
  let s: string;
  if (typeof v === "number") s = v !== 0 && (Math.abs(v) >= 1e7 || Math.abs(v) < 1e-4) ? v.toExponential() : String(v);
  else if (typeof v === "string") s = JSON.stringify(v.length > 24 ? `${v.slice(0, 24)}…` : v);
  else if (v === null) s = "null";
  else if (Array.isArray(v)) s = "a list";
  else if (typeof v === "object") s = "an object";
  else s = String(v);
  return s;
}

const isObject = (v: unknown): v is Record<string, unknown> => typeof v === "object" && v !== null && !Array.isArray(v);

/**
 * The state of a link as the page may use it: structure and hash checked (a [[LinkError]]
 * otherwise), unusable fields dropped and limited ones brought in range, each named in
 * `ignored`. Settings are checked for their basic type here (finite number, boolean or short
 * text); the page checks each against its own kind and range. A job's parts are checked
 * against `job` (the core's job schema).
 */
export function checkState(raw: unknown, job: JobSchema): { state: ShareState; ignored: string[] } {
  if (!isObject(raw)) throw new LinkError("its state is not a preview's state");
  const ignored: string[] = [];
  // a SHA-256 is 64 hexadecimal digits; fewer are accepted (they can only fail to match)
  if (typeof raw.sha256 !== "string" || !/^[0-9a-fA-F]{1,64}$/.test(raw.sha256)) {
    throw new LinkError("its model's SHA-256 is missing or not hexadecimal digits (at most 64)");
  }
  const sha256 = raw.sha256.toLowerCase();
  if (typeof raw.name !== "string") throw new LinkError("its model's name is missing");
  const name = raw.name.length > NAME_MAX ? `${raw.name.slice(0, NAME_MAX)}…` : raw.name;

  const settings: Record<string, Value> = {};
  if (raw.settings !== undefined) {
    if (!isObject(raw.settings)) throw new LinkError("its settings are not a list of settings");
    const entries = Object.entries(raw.settings);
    if (entries.length > SETTINGS_MAX) throw new LinkError(`it has ${nf.format(entries.length)} settings; at most ${SETTINGS_MAX} are accepted`);
    for (const [k, v] of entries) {
      const key = k.length > 40 ? `${k.slice(0, 40)}…` : k;
      if (!/^[a-z][a-z0-9_]{0,63}$/.test(k)) ignored.push(`a setting named ${JSON.stringify(key)}`);
      else if (typeof v === "number" && !Number.isFinite(v)) ignored.push(`its setting ${k} (${shown(v)} is not a finite number: the default is used)`);
      else if (typeof v === "string" && v.length > SETTING_TEXT_MAX) ignored.push(`its setting ${k} (a text of ${nf.format(v.length)} characters: the default is used)`);
      else if (typeof v === "number" || typeof v === "boolean" || typeof v === "string") settings[k] = v;
      else ignored.push(`its setting ${k} (${shown(v)} is not a number, a yes/no or a choice: the default is used)`);
    }
  }

  let layer: number | undefined;
  if (typeof raw.layer === "number" && Number.isFinite(raw.layer)) {
    // the page clamps it to the slice's layers once it knows how many there are
    layer = Math.max(0, Math.min(1e9, Math.round(raw.layer)));
  } else if (raw.layer !== undefined) {
    ignored.push(`its layer (${shown(raw.layer)} is not a layer number: a default layer is shown)`);
  }

  let view: View | undefined;
  if (raw.view !== undefined) {
    const v = raw.view;
    const finite = (x: unknown): x is number => typeof x === "number" && Number.isFinite(x);
    if (!isObject(v) || !finite(v.scale) || !finite(v.cx) || !finite(v.cy)) {
      ignored.push("its view (not three finite numbers: the part is fitted instead)");
    } else if (!(v.scale > 0)) {
      ignored.push(`its view (zoom ${shown(v.scale)} px/mm is not positive: the part is fitted instead)`);
    } else if (Math.abs(v.cx) > MAX_CENTRE_MM || Math.abs(v.cy) > MAX_CENTRE_MM) {
      ignored.push(`its view (centre ${shown(v.cx)}, ${shown(v.cy)} mm is beyond ±${nf.format(MAX_CENTRE_MM)} mm: the part is fitted instead)`);
    } else {
      const scale = Math.min(MAX_SCALE, Math.max(MIN_SCALE, v.scale));
      if (scale !== v.scale) ignored.push(`its zoom (${shown(v.scale)} px/mm, limited to ${scale} px/mm)`);
      view = { scale, cx: v.cx, cy: v.cy };
    }
  }

  let showTravel: boolean | undefined;
  if (typeof raw.showTravel === "boolean") showTravel = raw.showTravel;
  else if (raw.showTravel !== undefined) ignored.push(`its travel option (${shown(raw.showTravel)})`);

  const state: ShareState = { settings, name, sha256 };
  checkView(raw, state, ignored);
  if (raw.files !== undefined || raw.parts !== undefined) {
    state.files = checkFiles(raw.files, job);
    state.parts = checkParts(raw.parts, state.files, job, ignored);
  }
  if (layer !== undefined) state.layer = layer;
  if (view !== undefined) state.view = view;
  if (showTravel !== undefined) state.showTravel = showTravel;
  return { state, ignored };
}

const HEX = /^[0-9a-fA-F]{1,64}$/;

/** The link's stage: its mode, camera, cut line and overlays, each checked (finite, in range);
 *  a wrong one is dropped and named in `ignored`. */
function checkView(raw: Record<string, unknown>, state: ShareState, ignored: string[]): void {
  if (raw.mode === "layer" || raw.mode === "3d") state.mode = raw.mode;
  else if (raw.mode !== undefined) ignored.push(`its view mode (${shown(raw.mode)} is neither "layer" nor "3d": the layer view is shown)`);
  if (raw.camera !== undefined) {
    const c = raw.camera;
    const point = (p: unknown): p is [number, number, number] =>
      Array.isArray(p) && p.length === 3 && p.every((v) => typeof v === "number" && Number.isFinite(v) && Math.abs(v) <= CAMERA_MAX_MM);
    if (isObject(c) && point(c.position) && point(c.target) && Math.hypot(c.position[0] - c.target[0], c.position[1] - c.target[1], c.position[2] - c.target[2]) > 1e-3) {
      state.camera = { position: [...c.position], target: [...c.target] };
    } else {
      ignored.push(`its 3D camera (not two distinct points of three finite numbers within ±${nf.format(CAMERA_MAX_MM)} mm: the plate is framed instead)`);
    }
  }
  if (raw.cut !== undefined) {
    const line = checkLine(raw.cut);
    if (line) state.cut = line;
    else ignored.push("its cut line (not two distinct points within the page's limits: no cut is shown)");
  }
  if (raw.overlays !== undefined) {
    const o = raw.overlays;
    if (!isObject(o)) ignored.push(`its overlays (${shown(o)})`);
    else {
      const overlays: Overlays = {};
      for (const k of ["below", "voids", "overhangs"] as const) {
        if (typeof o[k] === "boolean") overlays[k] = o[k];
        else if (o[k] !== undefined) ignored.push(`its ${k === "below" ? "layer below" : k} overlay (${shown(o[k])})`);
      }
      state.overlays = overlays;
    }
  }
}

/** The job's files of a link: at most the core's `max_parts`, names of at most 255
 *  characters, distinct; hexadecimal hashes; sizes that add up to at most
 *  [[MODEL_MAX_BYTES]]. Anything else is a [[LinkError]] (the parts could not be matched to
 *  their files). */
function checkFiles(raw: unknown, job: JobSchema): LinkFile[] {
  if (!Array.isArray(raw) || raw.length === 0) throw new LinkError("its job's files are not a list of files");
  if (raw.length > job.max_parts) throw new LinkError(`its job lists ${nf.format(raw.length)} files; at most ${job.max_parts} are accepted`);
  const out: LinkFile[] = [];
  let total = 0;
  raw.forEach((f, i) => {
    if (!isObject(f)) throw new LinkError(`its job's file ${i + 1} is not a file`);
    if (typeof f.name !== "string" || f.name.length === 0 || f.name.length > NAME_MAX) throw new LinkError(`its job's file ${i + 1} has no name of 1 … ${NAME_MAX} characters`);
    if (out.some((o) => o.name === f.name)) throw new LinkError(`its job lists the file ${shown(f.name)} twice`);
    if (typeof f.sha256 !== "string" || !HEX.test(f.sha256)) throw new LinkError(`its job's file ${shown(f.name)} has no SHA-256 of hexadecimal digits (at most 64)`);
    if (typeof f.bytes !== "number" || !Number.isInteger(f.bytes) || f.bytes < 0 || f.bytes > MODEL_MAX_BYTES) throw new LinkError(`its job's file ${shown(f.name)} has no size of 0 … ${size(MODEL_MAX_BYTES)}`);
    total += f.bytes;
    if (total > MODEL_MAX_BYTES) throw new LinkError(`its job's files are more than ${size(MODEL_MAX_BYTES)} in all`);
    out.push({ name: f.name, sha256: f.sha256.toLowerCase(), bytes: f.bytes });
  });
  return out;
}

/** A 3MF build item's index: a whole number, bounded here only to keep the link's numbers
 *  sane (the core checks it against the file's items). */
const ITEM_MAX = 1_000_000;

/** The parts of a link: each names one of `files`; a number that is not finite or out of
 *  range is dropped (the default is used) and named in `ignored`; the core checks all again. */
function checkParts(raw: unknown, files: LinkFile[], job: JobSchema, ignored: string[]): PartSpec[] {
  if (!Array.isArray(raw) || raw.length === 0) throw new LinkError("its job's parts are not a list of parts");
  if (raw.length > job.max_parts) throw new LinkError(`its job has ${nf.format(raw.length)} parts; at most ${job.max_parts} are accepted`);
  return raw.map((p, i) => {
    const at = `its part ${i + 1}`;
    if (!isObject(p)) throw new LinkError(`${at} is not a part`);
    if (typeof p.file !== "string" || !files.some((f) => f.name === p.file)) throw new LinkError(`${at} names no file of the link`);
    const out: PartSpec = { file: p.file };
    for (const [k, v] of Object.entries(p)) {
      if (k === "file") continue;
      const spec = partNumber(job, k);
      if (k === "name") {
        if (typeof v === "string" && v.length <= NAME_MAX) out.name = v;
        else ignored.push(`${at}'s name (not a text of at most ${NAME_MAX} characters)`);
      } else if (k === "item") {
        if (typeof v === "number" && Number.isInteger(v) && v >= 0 && v <= ITEM_MAX) out.item = v;
        else ignored.push(`${at}'s item (${shown(v)} is not a whole number in 0 … ${ITEM_MAX}: the whole file is used)`);
      } else if (k === "mirror_x" || k === "mirror_y" || k === "mirror_z") {
        if (typeof v === "boolean") out[k] = v;
        else ignored.push(`${at}'s ${k} (${shown(v)} is not true or false: not mirrored)`);
      } else if (!spec) {
        ignored.push(`${at}'s ${/^[a-z_]{1,40}$/.test(k) ? k : "unknown key"} (not a part's setting)`);
      } else if (typeof v !== "number" || !fitsPart(spec, v)) {
        const whole = spec.kind === "integer";
        ignored.push(`${at}'s ${k} (${shown(v)} is not ${whole ? "a whole number" : "a number"} in ${spec.min_exclusive ? "(" : ""}${spec.min} … ${spec.max}: the default is used)`);
      } else {
        (out as unknown as Record<string, number>)[k] = v;
      }
    }
    if ((out.place_x === undefined) !== (out.place_y === undefined)) {
      ignored.push(`${at}'s place (x and y go together: the part is arranged)`);
      delete out.place_x;
      delete out.place_y;
    }
    return out;
  });
}

/** Reads a link's fragment (parts checked against `job`, the core's job schema); null when it
 *  holds no preview. Throws a [[LinkError]] on a link
 *  too large or damaged to read; a too large or damaged embedded model is reported in
 *  `modelError` (the state is still usable: the receiver can drop the file in). */
export async function readLink(hash: string, job: JobSchema): Promise<SharedLink | null> {
  const params = new URLSearchParams(hash.replace(/^#/, ""));
  const p = params.get("p");
  if (!p) return null;
  const packed = fromBase64Url(p, STATE_TEXT_MAX, "its state");
  const text = new TextDecoder().decode(await inflate(packed, STATE_MAX_BYTES, "its state"));
  let raw: unknown;
  try {
    raw = JSON.parse(text);
  } catch {
    throw new LinkError("its state is not readable (the link may have been cut or changed)");
  }
  const { state, ignored } = checkState(raw, job);
  const m = params.get("m");
  let model: Uint8Array | null = null;
  let models: Uint8Array[] | null = null;
  let modelError: string | undefined;
  if (m) {
    const what = state.files && state.files.length > 1 ? "its models" : "its model";
    try {
      model = await inflate(fromBase64Url(m, MODEL_TEXT_MAX, what), MODEL_MAX_BYTES, what);
      models = state.files ? split(model, state.files) : [model];
    } catch (e) {
      if (!(e instanceof LinkError)) throw e;
      model = models = null;
      modelError = e.message;
    }
  }
  return { state, model, models, modelError, ignored };
}

/** The embedded bytes cut into the files' sizes, which must add up to them exactly. */
function split(bytes: Uint8Array, files: LinkFile[]): Uint8Array[] {
  const total = files.reduce((n, f) => n + f.bytes, 0);
  if (total !== bytes.length) throw new LinkError(`its models are ${nf.format(bytes.length)} bytes, not the ${nf.format(total)} bytes its files add up to`);
  let at = 0;
  return files.map((f) => bytes.subarray(at, (at += f.bytes)));
}

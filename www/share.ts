// Preview links: settings, layer, view and the model in the URL fragment (never sent to a
// server). The model is embedded (deflate-raw, base64url) when it compresses to at most
// 256 KB; otherwise the link carries its SHA-256 and file name, and the receiver drops in
// the same file, which the page checks against the hash.

import type { View } from "./render";

export const EMBED_LIMIT = 256 * 1024;

export interface ShareState {
  /** Settings that differ from the defaults. */
  settings: Record<string, number | boolean | string>;
  layer: number;
  view: View;
  name: string;
  sha256: string;
  showTravel?: boolean;
}

export interface SharedLink {
  state: ShareState;
  /** The model, when it was embedded. */
  model: Uint8Array | null;
}

async function pipe(bytes: Uint8Array, stream: CompressionStream | DecompressionStream): Promise<Uint8Array> {
  const out = new Blob([bytes as BlobPart]).stream().pipeThrough(stream);
  return new Uint8Array(await new Response(out).arrayBuffer());
}

export const deflate = (b: Uint8Array) => pipe(b, new CompressionStream("deflate-raw"));
export const inflate = (b: Uint8Array) => pipe(b, new DecompressionStream("deflate-raw"));

export function toBase64Url(bytes: Uint8Array): string {
  let bin = "";
  const chunk = 0x8000;
  for (let i = 0; i < bytes.length; i += chunk) {
    bin += String.fromCharCode(...bytes.subarray(i, i + chunk));
  }
  return btoa(bin).replace(/\+/g, "-").replace(/\//g, "_").replace(/=+$/, "");
}

export function fromBase64Url(text: string): Uint8Array {
  const b64 = text.replace(/-/g, "+").replace(/_/g, "/");
  const bin = atob(b64 + "===".slice((b64.length + 3) % 4));
  const out = new Uint8Array(bin.length);
  for (let i = 0; i < bin.length; i++) out[i] = bin.charCodeAt(i);
  return out;
}

export async function sha256Hex(bytes: Uint8Array): Promise<string> {
  const digest = await crypto.subtle.digest("SHA-256", bytes as BufferSource);
  return [...new Uint8Array(digest)].map((b) => b.toString(16).padStart(2, "0")).join("");
}

/** Builds the link; `embedded` tells whether the model travels inside it. */
export async function makeLink(base: string, state: ShareState, model: Uint8Array): Promise<{ url: string; embedded: boolean }> {
  const p = toBase64Url(await deflate(new TextEncoder().encode(JSON.stringify(state))));
  const packed = await deflate(model);
  const embedded = packed.length <= EMBED_LIMIT;
  const url = `${base.split("#")[0]}#p=${p}${embedded ? `&m=${toBase64Url(packed)}` : ""}`;
  return { url, embedded };
}

/** Reads a link's fragment; null when it holds no preview. Throws on a damaged link. */
export async function readLink(hash: string): Promise<SharedLink | null> {
  const params = new URLSearchParams(hash.replace(/^#/, ""));
  const p = params.get("p");
  if (!p) return null;
  const state = JSON.parse(new TextDecoder().decode(await inflate(fromBase64Url(p)))) as ShareState;
  if (typeof state !== "object" || state === null || typeof state.sha256 !== "string") {
    throw new Error("the preview link is damaged");
  }
  const m = params.get("m");
  const model = m ? await inflate(fromBase64Url(m)) : null;
  return { state, model };
}

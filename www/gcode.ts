// Reading a .gco file back into droplets (viewer for existing machine code).
// G01 = travel, G25 = a line of droplets one every B from the current position
// (the first one at the current position), G26 = travel + one droplet.
// B = droplet_aspect x layer_height, read from the header's "; name = value" lines.

import type { Counts, LayerData } from "./protocol";

class Growable<T extends Float32Array | Uint8Array> {
  private buf: T;
  length = 0;
  constructor(private make: (n: number) => T) {
    this.buf = make(1024);
  }
  push(v: number): void {
    if (this.length === this.buf.length) {
      const next = this.make(this.buf.length * 2);
      next.set(this.buf);
      this.buf = next;
    }
    this.buf[this.length++] = v;
  }
  take(): T {
    return this.buf.slice(0, this.length) as T;
  }
}

interface LayerBuilder {
  z: number;
  droplets: Growable<Float32Array>;
  roles: Growable<Uint8Array>;
  travel: Growable<Float32Array>;
  counts: Counts;
  travelMm: number;
}

function newLayer(z: number): LayerBuilder {
  return {
    z,
    droplets: new Growable((n) => new Float32Array(n)),
    roles: new Growable((n) => new Uint8Array(n)),
    travel: new Growable((n) => new Float32Array(n)),
    counts: { outer: 0, inner: 0, fill: 0 },
    travelMm: 0,
  };
}

export class GcodeError extends Error {}

// Limits of the viewer. A .gco file may come from anyone: these keep a crafted file from
// freezing the page or filling its memory (each droplet costs 9 bytes, twice while a layer
// grows), while every file the slicer writes for a real printer stays well inside them.

/** Coordinates beyond ±100 m are refused (no printer is that big; far beyond, the view and
 *  the float32 droplet arrays lose all precision). */
export const MAX_COORD_MM = 1e5;
/** The header's droplet size must be within the core's settings ranges (src/settings.rs,
 *  `schema()`: layer_height > 0 and ≤ 5 mm, droplet_aspect > 0 and ≤ 10). */
export const LAYER_HEIGHT_MAX = 5;
export const DROPLET_ASPECT_MAX = 10;
/** Droplets expanded from one file (G25 lines and G26): 50 million, about 450 MB in the page.
 *  3DBenchy at the default settings has about 2 million. */
export const MAX_DROPLETS = 50_000_000;
/** A line longer than this (1 MB) is refused rather than gathered in memory. */
export const MAX_LINE_CHARS = 1 << 20;
/** Travel moves (G01) kept for drawing: 20 million, about 320 MB. */
export const MAX_TRAVEL_MOVES = 20_000_000;
/** Layers (distinct heights): 100,000, e.g. 1 m at 0.01 mm. */
export const MAX_LAYERS = 100_000;

const nfmt = new Intl.NumberFormat("en-US");

/** A count for a message: "96 million", "1.2e+300", "12,345". */
function count(n: number): string {
  if (!Number.isFinite(n)) return "countless";
  if (n >= 1e15) return n.toExponential(1);
  if (n >= 1e7) return `${nfmt.format(Math.round(n / 1e6))} million`;
  return nfmt.format(n);
}

/** Streaming parser: feed lines, get finished layers through the callback. */
export class GcodeReader {
  header: Record<string, string> = {};
  private width = NaN;
  private x = 0;
  private y = 0;
  private z = 0;
  private layer: LayerBuilder | null = null;
  private index = 0;
  private lineNo = 0;
  private commands = 0;
  private droplets = 0;
  private travels = 0;

  constructor(private emit: (layer: LayerData) => void) {}

  get dropletWidth(): number {
    return this.width;
  }
  get layers(): number {
    return this.index;
  }
  /** Lines read so far. */
  get lineNumber(): number {
    return this.lineNo;
  }

  line(raw: string): void {
    this.lineNo++;
    const line = raw.trim();
    if (line === "") return;
    if (line.startsWith(";")) {
      this.comment(line.slice(1).trim());
      return;
    }
    const code = line.slice(0, 3).toUpperCase();
    if (code !== "G01" && code !== "G25" && code !== "G26") {
      throw new GcodeError(`line ${this.lineNo}: "${line.slice(0, 40)}" is not a G01, G25 or G26 command`);
    }
    if (!(this.width > 0)) {
      throw new GcodeError(
        "the header does not give the droplet size (lines '; layer_height = …' and '; droplet_aspect = …' are needed before the first command)",
      );
    }
    let x = this.x;
    let y = this.y;
    let z = this.z;
    for (const word of line.slice(3).trim().split(/\s+/)) {
      if (word === "" || word.startsWith(";")) break;
      const v = word.length > 1 ? Number(word.slice(1)) : NaN;
      const shown = word.length > 40 ? `${word.slice(0, 40)}…` : word;
      if (!Number.isFinite(v)) throw new GcodeError(`line ${this.lineNo}: bad number in "${shown}"`);
      if (Math.abs(v) > MAX_COORD_MM) {
        throw new GcodeError(
          `line ${this.lineNo}: the coordinate "${shown}" is too far out: this viewer reads coordinates up to ±${nfmt.format(MAX_COORD_MM)} mm`,
        );
      }
      switch (word[0].toUpperCase()) {
        case "X": x = v; break;
        case "Y": y = v; break;
        case "Z": z = v; break;
        default: throw new GcodeError(`line ${this.lineNo}: unknown word "${shown}"`);
      }
    }
    // what this line adds, checked before anything is stored
    let n = 0;
    const len = Math.hypot(x - this.x, y - this.y);
    if (code === "G25") {
      // As the core counts (plan::line_droplets, from the written 4-decimal coordinates).
      n = Math.floor(len / this.width + 1e-9) + 1;
      if (!(this.droplets + n <= MAX_DROPLETS)) {
        throw new GcodeError(
          n > MAX_DROPLETS / 10 || !Number.isFinite(n)
            ? `line ${this.lineNo}: a G25 of ${+len.toPrecision(6)} mm would expand to ${count(n)} droplets (one every ${+this.width.toPrecision(4)} mm); this viewer expands at most ${count(MAX_DROPLETS)} droplets per file`
            : `line ${this.lineNo}: the file holds more than ${count(MAX_DROPLETS)} droplets, the most this viewer expands; it was not opened`,
        );
      }
    } else if (code === "G26") {
      n = 1;
      if (this.droplets + 1 > MAX_DROPLETS) {
        throw new GcodeError(`line ${this.lineNo}: the file holds more than ${count(MAX_DROPLETS)} droplets, the most this viewer expands; it was not opened`);
      }
    } else if (++this.travels > MAX_TRAVEL_MOVES) {
      throw new GcodeError(`line ${this.lineNo}: the file holds more than ${count(MAX_TRAVEL_MOVES)} travel moves (G01), the most this viewer shows; it was not opened`);
    }
    this.droplets += n;
    this.commands++;
    if (this.layer === null || Math.abs(z - this.layer.z) > 1e-6) {
      if (this.index + 1 >= MAX_LAYERS && this.layer !== null) {
        throw new GcodeError(`line ${this.lineNo}: the file has more than ${nfmt.format(MAX_LAYERS)} layers (heights), the most this viewer shows; it was not opened`);
      }
      this.flush();
      this.layer = newLayer(z);
    }
    const L = this.layer;
    if (code === "G01") {
      L.travel.push(this.x); L.travel.push(this.y); L.travel.push(x); L.travel.push(y);
      L.travelMm += len;
    } else if (code === "G26") {
      if (x !== this.x || y !== this.y) {
        L.travelMm += len;
      }
      // G-code does not say which loop a droplet belongs to: every G26 droplet counts as a
      // loop droplet (role 0), every G25 droplet as fill (role 2).
      L.droplets.push(x); L.droplets.push(y); L.roles.push(0);
      L.counts.outer++;
    } else {
      const dx = x - this.x;
      const dy = y - this.y;
      for (let k = 0; k < n; k++) {
        const t = len > 0 ? (k * this.width) / len : 0;
        L.droplets.push(this.x + dx * t); L.droplets.push(this.y + dy * t); L.roles.push(2);
      }
      L.counts.fill += n;
    }
    this.x = x; this.y = y; this.z = z;
  }

  private comment(text: string): void {
    const m = /^([a-z_]+)\s*=\s*(\S+)/.exec(text);
    if (m && this.commands === 0) {
      const [, name, value] = m;
      const max = name === "layer_height" ? LAYER_HEIGHT_MAX : name === "droplet_aspect" ? DROPLET_ASPECT_MAX : null;
      if (max !== null) {
        // the droplet size decides how many droplets a G25 line holds: only the core's range
        const v = Number(value);
        if (!(v > 0 && v <= max)) {
          const shown = value.length > 40 ? `${value.slice(0, 40)}…` : value;
          throw new GcodeError(
            `line ${this.lineNo}: the header's ${name} = ${shown} is out of range: it must be greater than 0 and at most ${max}${name === "layer_height" ? " mm" : ""}`,
          );
        }
      }
      this.header[name] = value;
      const h = Number(this.header.layer_height);
      const a = Number(this.header.droplet_aspect ?? "1.04");
      if (h > 0 && a > 0) this.width = h * a;
    }
  }

  flush(): void {
    const L = this.layer;
    if (!L) return;
    this.layer = null;
    this.emit({
      index: this.index++,
      z: L.z,
      counts: L.counts,
      travelMm: L.travelMm,
      droplets: L.droplets.take(),
      roles: L.roles.take(),
      travel: L.travel.take(),
    });
  }

  finish(): void {
    this.flush();
    if (this.commands === 0) throw new GcodeError("the file holds no G01/G25/G26 commands");
  }
}

/** Reads a whole .gco Blob as a stream of lines; `progress` gets the share of bytes read. */
export async function readGcode(file: Blob, reader: GcodeReader, progress?: (fraction: number) => void): Promise<void> {
  let bytes = 0;
  const counter = new TransformStream<Uint8Array<ArrayBuffer>, Uint8Array<ArrayBuffer>>({
    transform(chunk, controller) {
      bytes += chunk.byteLength;
      progress?.(file.size > 0 ? bytes / file.size : 1);
      controller.enqueue(chunk);
    },
  });
  const stream = file.stream().pipeThrough(counter).pipeThrough(new TextDecoderStream());
  const r = stream.getReader();
  let rest = "";
  try {
    for (;;) {
      const { value, done } = await r.read();
      if (done) break;
      const text = rest + value;
      let start = 0;
      for (;;) {
        const nl = text.indexOf("\n", start);
        if (nl < 0) break;
        reader.line(text.slice(start, nl));
        start = nl + 1;
      }
      rest = text.slice(start);
      if (rest.length > MAX_LINE_CHARS) {
        throw new GcodeError(`line ${reader.lineNumber + 1} is longer than ${nfmt.format(MAX_LINE_CHARS)} characters; this is not a G-code file this viewer reads`);
      }
    }
  } catch (e) {
    // stop reading the file: the rest of it is not needed
    r.cancel().catch(() => {});
    throw e;
  }
  if (rest) reader.line(rest);
  reader.finish();
}

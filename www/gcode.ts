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

  constructor(private emit: (layer: LayerData) => void) {}

  get dropletWidth(): number {
    return this.width;
  }
  get layers(): number {
    return this.index;
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
      const v = Number(word.slice(1));
      if (!Number.isFinite(v)) throw new GcodeError(`line ${this.lineNo}: bad number in "${word}"`);
      switch (word[0].toUpperCase()) {
        case "X": x = v; break;
        case "Y": y = v; break;
        case "Z": z = v; break;
        default: throw new GcodeError(`line ${this.lineNo}: unknown word "${word}"`);
      }
    }
    this.commands++;
    if (this.layer === null || Math.abs(z - this.layer.z) > 1e-6) {
      this.flush();
      this.layer = newLayer(z);
    }
    const L = this.layer;
    if (code === "G01") {
      L.travel.push(this.x); L.travel.push(this.y); L.travel.push(x); L.travel.push(y);
      L.travelMm += Math.hypot(x - this.x, y - this.y);
    } else if (code === "G26") {
      if (x !== this.x || y !== this.y) {
        L.travelMm += Math.hypot(x - this.x, y - this.y);
      }
      // G-code does not say which loop a droplet belongs to: every G26 droplet counts as a
      // loop droplet (role 0), every G25 droplet as fill (role 2).
      L.droplets.push(x); L.droplets.push(y); L.roles.push(0);
      L.counts.outer++;
    } else {
      const dx = x - this.x;
      const dy = y - this.y;
      const len = Math.hypot(dx, dy);
      // As the core counts (plan::line_droplets, from the written 4-decimal coordinates).
      const n = Math.floor(len / this.width + 1e-9) + 1;
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
      this.header[m[1]] = m[2];
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
  }
  if (rest) reader.line(rest);
  reader.finish();
}

// Reading a .gco file back into droplets (viewer for existing machine code): a thin wrapper
// of the core's reader (src/output/gcode_read/, through src/wasm/reader.rs), which owns the rules
// (G01 travel, G25 a droplet every B from the current position, G26 one droplet; B from the
// header) and the bounds a file from anyone must keep (coordinates, droplets, travel moves,
// layers, line length), with the messages that name the line and the reason.

import { GcodeStream, initSync, type InitOutput } from "../pkg/dropslice.js";
import type { Calibration, Figures, LayerData } from "../core/protocol";
import { partsByUnit } from "../core/units";

export class GcodeError extends Error {}

let core: InitOutput | null = null;

/** Instantiates the core (once; later calls return the first instance). `source`: the module
 *  the page compiled (the worker's first message), or its bytes (tests in Node). Nothing here
 *  fetches the module. */
export function loadCore(source: BufferSource | WebAssembly.Module): InitOutput {
  core ??= initSync({ module: source });
  return core;
}

/** The reader's refusals become GcodeErrors; a crash of the core stays what it is. */
function refusal(e: unknown): unknown {
  if (e instanceof WebAssembly.RuntimeError || !(e instanceof Error)) return e;
  return new GcodeError(e.message);
}

/** Streaming reader (the core is loaded first: [[loadCore]]): feed text or lines, get finished
 *  layers through the callback. */
export class GcodeReader {
  private s: GcodeStream | null = null;

  /** `counting`: the core keeps counts only (layers come without droplets, roles or travel),
   *  for [[calibrate]]. */
  constructor(
    private emit: (layer: LayerData) => void,
    private counting = false,
  ) {}

  private get stream(): GcodeStream {
    this.s ??= this.counting ? GcodeStream.counting() : new GcodeStream();
    return this.s;
  }

  /** After [[finish]]: the core's calibration of the file for a measured `mass` (g) and
   *  `density` (g/cm³; null: the header's material_density, else the default). Throws the
   *  core's refusal as a plain Error (not a GcodeError: the file itself was read). */
  calibrate(mass: number, density: number | null): Calibration {
    return this.stream.calibrate(mass, density ?? undefined);
  }

  /** After [[finish]]: the file's figures with its header's settings; throws the core's
   *  reason ({kind, message}) when the header does not give them. */
  figures(): Figures {
    return this.stream.figures();
  }

  /** After [[finish]]: why [[figures]] are computed from the commands; null when they are
   *  the header's own (the slice's). */
  figuresNote(): string | null {
    return this.stream.figures_note() ?? null;
  }

  /** The settings the header names, typed and checked by the core; throws the core's reason
   *  ({kind, message}) when they do not pass. */
  headerSettings(): Record<string, number | boolean | string> {
    return this.stream.header_settings();
  }

  /** Frees the core's reader (the object is unusable afterwards). */
  free(): void {
    this.s?.free();
    this.s = null;
  }

  /** The header's `name = value` lines (before the first command). */
  get header(): Record<string, string> {
    return this.stream.header() as Record<string, string>;
  }
  get dropletWidth(): number {
    return this.stream.droplet_width;
  }
  get layers(): number {
    return this.stream.layers;
  }
  /** Lines read so far. */
  get lineNumber(): number {
    return this.stream.line_number;
  }

  /** One line of the file. */
  line(raw: string): void {
    this.feed(`${raw}\n`);
  }

  /** A piece of the file (lines may be split across pieces). */
  feed(text: string): void {
    try {
      this.stream.feed(text);
    } catch (e) {
      throw refusal(e);
    }
    this.drain();
  }

  private drain(): void {
    for (let l = this.stream.take_layer(); l; l = this.stream.take_layer()) {
      const [outer, inner, fill] = l.counts();
      const roles = l.roles();
      const units = l.units();
      this.emit({
        index: l.index,
        z: l.z,
        counts: { outer, inner, fill, support: 0, units: Array.from(l.unit_droplets), parts: partsByUnit(roles, units) },
        travelMm: l.travel_mm,
        droplets: l.droplets(),
        roles,
        units,
        travel: l.travel(),
      });
      l.free();
    }
  }

  finish(): void {
    try {
      this.stream.finish();
    } catch (e) {
      throw refusal(e);
    }
    this.drain();
  }
}

/** Reads a whole .gco Blob as a stream of text; `progress` gets the share of bytes read. */
export async function readGcode(file: Blob, reader: GcodeReader, progress?: (fraction: number) => void): Promise<void> {
  if (!core) throw new Error("the slicer's module is not loaded in this worker");
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
  try {
    for (;;) {
      const { value, done } = await r.read();
      if (done) break;
      reader.feed(value);
    }
  } catch (e) {
    // stop reading the file: the rest of it is not needed
    r.cancel().catch(() => {});
    throw e;
  }
  reader.finish();
}

// The droplet calibration, run in a worker for views/calibrate.ts: every figure is the core's
// (src/output/calibrate.rs through src/wasm/reader.rs). A slice's calibration is one call with its
// droplet total, H and aspect; a .gco file is read again by the core's counting reader (its
// header's total, else its commands' droplets; its H, aspect and material_density).
// Refusals become errors of kind "calibration" with the core's message, a file that cannot be
// read one of kind "import"; a crash of the core stays what it is.

import { calibrate } from "../pkg/dropslice.js";
import { GcodeError, GcodeReader, readGcode } from "./gcode";
import { isErrorValue, type CalibrateRequest, type Calibration, type ErrorValue } from "../core/protocol";

function refused(e: unknown): unknown {
  if (e instanceof GcodeError) return { kind: "import", message: `cannot read the G-code file: ${e.message}` } satisfies ErrorValue;
  if (e instanceof WebAssembly.RuntimeError || isErrorValue(e) || !(e instanceof Error)) return e;
  return { kind: "calibration", message: e.message } satisfies ErrorValue;
}

/** The core's calibration for `req` (the core is loaded by the caller). */
export async function calibrateRequest(req: CalibrateRequest): Promise<Calibration> {
  try {
    if (req.from === "slice") return calibrate(req.droplets, req.layer_height, req.droplet_aspect, req.mass, req.density);
    const reader = new GcodeReader(() => {}, true);
    try {
      await readGcode(req.file, reader);
      return reader.calibrate(req.mass, req.density);
    } finally {
      reader.free();
    }
  } catch (e) {
    throw refused(e);
  }
}

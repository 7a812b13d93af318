// The longest calls into the core on the page's path, in Node on one thread (CPU ms of each
// call by process.cpuUsage, so that a loaded machine's waiting does not count): the job's
// preparation (in short calls, `Session.begin` + `Preparing.step`, where the module has them;
// else the one call `Session.from_models`) and every layer (`slice_layer`), PASSES times in a
// row from a module just loaded (the first pass runs while the engine still compiles).
// Prints each pass' preparation (all its calls, the longest, each in order) and layers (all,
// the longest).
// Usage: node scripts/wasm_call_time.mjs [PASSES] [MODEL.stl] [PKG_DIR]   (`bash scripts/build.sh`
// first; PKG_DIR: the wasm-bindgen output to time, www/pkg by default)
import { readFileSync } from "node:fs";
import { basename, dirname, join, resolve } from "node:path";
import { fileURLToPath, pathToFileURL } from "node:url";

const repo = resolve(dirname(fileURLToPath(import.meta.url)), "..");
const passes = Number(process.argv[2] ?? 3);
if (!Number.isInteger(passes) || passes < 1 || passes > 50) throw new Error(`expected 1 to 50 passes, got ${process.argv[2]}`);
const model = process.argv[3] || join(repo, "../shared/models/3DBenchy.stl");
const pkg = resolve(process.argv[4] || join(repo, "www/pkg"));
const core = await import(pathToFileURL(join(pkg, "dropslice.js")).href);
core.initSync({ module: readFileSync(join(pkg, "dropslice_bg.wasm")) });
const cpuMs = () => {
  const u = process.cpuUsage();
  return (u.user + u.system) / 1e3;
};
/** Runs `f`, adding its CPU ms to `acc` (sum and longest). */
function timed(acc, f) {
  const t0 = cpuMs();
  try {
    return f();
  } finally {
    const t = cpuMs() - t0;
    acc.sum += t;
    acc.max = Math.max(acc.max, t);
    acc.calls++;
    acc.each?.push(t);
  }
}
const name = basename(model);
const models = new core.Models();
models.add_bytes(readFileSync(model), name);
const job = { settings: {}, parts: [{ file: name }] };
const stepped = typeof core.Session.begin === "function";
for (let k = 0; k < passes; k++) {
  const prep = { sum: 0, max: 0, calls: 0, each: [] };
  let s;
  if (stepped) {
    const p = timed(prep, () => core.Session.begin(models, job));
    while (!timed(prep, () => p.step()));
    s = core.Session.from_preparation(p);
  } else {
    s = timed(prep, () => core.Session.from_models(models, job));
  }
  const layers = { sum: 0, max: 0, calls: 0 };
  for (let i = 0; i < s.layer_count(); i++) timed(layers, () => s.slice_layer(i)).free();
  s.free();
  const f = (a) => `${a.sum.toFixed(0)} ms in ${a.calls} calls, the longest ${a.max.toFixed(1)} ms`;
  console.log(`pass ${k + 1}: preparation ${f(prep)} (${prep.each.map((t) => t.toFixed(0)).join(", ")}); layers ${f(layers)}`);
}

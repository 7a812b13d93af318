// The longest calls into the core on the page's path, in Node on one thread (CPU ms of each
// call by process.cpuUsage, so that a loaded machine's waiting does not count): the job's
// preparation (in short calls, `Session.begin` + `Preparing.step`, where the module has them;
// else the one call `Session.from_models`) and every layer (`slice_layer`), PASSES times in a
// row from a module just loaded (the first pass runs while the engine still compiles).
// Prints each pass' preparation (all its calls, the longest, each in order) and layers (all,
// the longest).
// Also the file's import (`Models.add_bytes`), the hand-off to another worker
// (`Session.prepared`, `Session.from_prepared`) and, with SETTINGS, a job of other settings
// (`'{"support":"unit1"}'`: its first layer runs the supported pass).
// The supported pass runs SUPPORT_ITEMS (environment, 4 as the page) layers' worth a call; its
// calls over 10 ms are listed (call number: ms).
// Usage: node scripts/wasm_call_time.mjs [PASSES] [MODEL.stl] [PKG_DIR] [ITEMS] [SETTINGS]
// (`bash scripts/build.sh` first; PKG_DIR: the wasm-bindgen output to time, www/pkg by
// default; ITEMS: the preparation's items per call, 16384 as the page)
import { readFileSync } from "node:fs";
import { basename, dirname, join, resolve } from "node:path";
import { fileURLToPath, pathToFileURL } from "node:url";

const repo = resolve(dirname(fileURLToPath(import.meta.url)), "..");
const passes = Number(process.argv[2] ?? 3);
if (!Number.isInteger(passes) || passes < 1 || passes > 50) throw new Error(`expected 1 to 50 passes, got ${process.argv[2]}`);
const model = process.argv[3] || join(repo, "../shared/models/3DBenchy.stl");
const pkg = resolve(process.argv[4] || join(repo, "www/pkg"));
const items = Number(process.argv[5] || 16384);
const settings = JSON.parse(process.argv[6] || "{}");
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
const bytes = readFileSync(model);
const add = { sum: 0, max: 0, calls: 0 };
timed(add, () => models.add_bytes(bytes, name));
console.log(`import (Models.add_bytes): ${add.max.toFixed(1)} ms`);
const job = { settings, parts: [{ file: name }] };
const stepped = typeof core.Session.begin === "function";
for (let k = 0; k < passes; k++) {
  const prep = { sum: 0, max: 0, calls: 0, each: [] };
  let s;
  if (stepped) {
    const p = timed(prep, () => core.Session.begin(models, job));
    while (!timed(prep, () => (p.step.length > 0 ? p.step(items) : p.step())));
    s = core.Session.from_preparation(p);
  } else {
    s = timed(prep, () => core.Session.from_models(models, job));
  }
  const hand = { sum: 0, max: 0, calls: 0 };
  const bytesOut = timed(hand, () => s.prepared());
  timed(hand, () => core.Session.from_prepared(bytesOut)).free();
  const support = { sum: 0, max: 0, calls: 0, each: [] };
  const supportItems = Number(process.env.SUPPORT_ITEMS || 4);
  if (typeof s.support_step === "function") while (!timed(support, () => s.support_step(supportItems)));
  const layers = { sum: 0, max: 0, calls: 0, each: [] };
  for (let i = 0; i < s.layer_count(); i++) timed(layers, () => s.slice_layer(i)).free();
  s.free();
  const f = (a) => `${a.sum.toFixed(0)} ms in ${a.calls} calls, the longest ${a.max.toFixed(1)} ms`;
  const longest = (a) => {
    const i = a.each.indexOf(a.max);
    return `layer ${i}`;
  };
  const shown = prep.each.length > 24 ? `${prep.each.slice(0, 24).map((t) => t.toFixed(0)).join(", ")}, …` : prep.each.map((t) => t.toFixed(0)).join(", ");
  const over = support.each.flatMap((t, i) => (t > 10 ? [`${i}: ${t.toFixed(0)}`] : []));
  if (over.length > 0) console.log(`pass ${k + 1}: supported pass' calls over 10 ms (${over.length}): ${over.join(", ")}`);
  console.log(`pass ${k + 1}: preparation ${f(prep)} (${shown}); hand-off (prepared, from_prepared) ${f(hand)}; supported pass ${f(support)}; layers ${f(layers)} (${longest(layers)})`);
}

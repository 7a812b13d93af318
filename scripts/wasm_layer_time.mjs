// CPU seconds of the page's per-layer work in the core, on one thread in Node (no browser, no
// other worker): every layer of MODEL sliced (`slice_layer`) and sliced with analysis
// (`slice_layer_analysed`, reading the analysis and the mask out as the worker does), runs
// alternated, best of RUNS; and each pass' preparation (`new Session`, wall ms), the first of
// which is the first after the module loaded, as in a page just opened (docs/performance.md:
// about twice the later ones). Usage: node scripts/wasm_layer_time.mjs [RUNS] [MODEL.stl] [PKG_DIR]
// (PKG_DIR: the wasm-bindgen output to time, www/pkg by default; `bash scripts/build.sh` first).
import { readFileSync } from "node:fs";
import { resolve, dirname, join } from "node:path";
import { fileURLToPath, pathToFileURL } from "node:url";

const repo = resolve(dirname(fileURLToPath(import.meta.url)), "..");
const runs = Number(process.argv[2] ?? 3);
const model = process.argv[3] || join(repo, "../shared/models/3DBenchy.stl");
const pkg = resolve(process.argv[4] || join(repo, "www/pkg"));
const core = await import(pathToFileURL(join(pkg, "dropslice.js")).href);
core.initSync({ module: readFileSync(join(pkg, "dropslice_bg.wasm")) });
const stl = readFileSync(model);
const cpu = () => {
  const u = process.cpuUsage();
  return (u.user + u.system) / 1e6;
};

const prepared = [];

function pass(analyse) {
  const p0 = performance.now();
  const s = new core.Session(stl, model.split("/").pop(), core.default_settings());
  prepared.push(performance.now() - p0);
  const t0 = cpu();
  let sink = 0;
  for (let i = 0; i < s.layer_count(); i++) {
    const r = analyse ? s.slice_layer_analysed(i) : s.slice_layer(i);
    sink += r.droplets.length + r.gcode.length;
    if (analyse) {
      sink += r.analysis().voids;
      sink += r.mask_tiles.length + r.void_mask.length;
      if (typeof r.mask_overfilled === "undefined" || r.mask_overfilled.includes(1)) sink += r.overfill_mask.length;
    }
    r.free();
  }
  const t = cpu() - t0;
  s.free();
  return [t, sink];
}

const best = { plain: Infinity, analysed: Infinity };
for (let k = 0; k < runs; k++) {
  const [a] = pass(false);
  const [b] = pass(true);
  best.plain = Math.min(best.plain, a);
  best.analysed = Math.min(best.analysed, b);
  console.log(`run ${k}: sliced ${a.toFixed(2)} s, sliced + analysed ${b.toFixed(2)} s (CPU)`);
}
console.log(`prepared (ms, in order; the first after the module loaded): ${prepared.map((t) => t.toFixed(0)).join(", ")}`);
console.log(`best: sliced ${best.plain.toFixed(2)} s, sliced + analysed ${best.analysed.toFixed(2)} s, analysis ${(best.analysed - best.plain).toFixed(2)} s (CPU, one thread)`);

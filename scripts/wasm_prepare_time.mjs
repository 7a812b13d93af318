// The page's preparation of a model (`new Session`: import, checks, shells, facet index) in
// Node, three times in one module instance, after an optional warm-up preparation of another
// model, then every layer: the first preparation after the module loads is the page's case
// (docs/performance.md). Usage, after `bash scripts/build.sh`:
//   node scripts/wasm_prepare_time.mjs [MODEL.stl] [WARM-UP.stl] [PKG_DIR]
import { readFileSync } from "node:fs";
import { dirname, join, resolve } from "node:path";
import { fileURLToPath, pathToFileURL } from "node:url";

const repo = resolve(dirname(fileURLToPath(import.meta.url)), "..");
const model = process.argv[2] || join(repo, "../shared/models/3DBenchy.stl");
const warm = process.argv[3] || "";
const pkg = resolve(process.argv[4] || join(repo, "www/pkg"));
const core = await import(pathToFileURL(join(pkg, "dropslice.js")).href);
core.initSync({ module: readFileSync(join(pkg, "dropslice_bg.wasm")) });

if (warm) {
  const t = performance.now();
  const w = new core.Session(readFileSync(warm), warm.split("/").pop(), core.default_settings());
  w.free();
  console.log(`warm-up preparation of ${warm.split("/").pop()}: ${(performance.now() - t).toFixed(0)} ms`);
}
const stl = readFileSync(model);
for (let run = 1; run <= 3; run++) {
  let t = performance.now();
  const s = new core.Session(stl, model.split("/").pop(), core.default_settings());
  const prepare = performance.now() - t;
  t = performance.now();
  for (let i = 0; i < s.layer_count(); i++) s.slice_layer(i).free();
  console.log(`run ${run}: prepared in ${prepare.toFixed(0)} ms, every layer in ${(performance.now() - t).toFixed(0)} ms (one thread)`);
  s.free();
}

// The calls into the core on the page's path, in Node on one thread (CPU ms of each call on
// the calling thread, so that a loaded machine's waiting does not count), PASSES times in a row
// from a module just loaded (the first pass runs while the engine still compiles the code):
// the file's import (`Models.begin_add_bytes` + `Adding.step` + `finish_add` where the module has them, else
// `Models.add_bytes`), the job's preparation with its draft (`Session.begin_drafted` +
// `Preparing.step` + `take_draft`, as the job worker of a page of two workers or more; else
// `Session.begin` or the one call `Session.from_models`), the draft taken and confirmed
// (`Session.from_draft`, `confirm`, as another worker), the hand-off of the prepared job
// (`Session.prepared`, `Session.from_prepared`), the supported pass (with SETTINGS
// `'{"support":"unit1"}'`) and every layer (`slice_layer`).
// Prints each pass' figures per kind of call and every call over LIMIT ms (environment, 10)
// by name.
// The preparation works through ITEMS items a call (16384 as the page), the import through
// IMPORT_ITEMS triangles (environment, 65536 as the page), the job taken (`Session.begin_take`,
// `Taking.step`) and written (`Session.begin_prepared`, `Writing.step`) TAKE_ITEMS items
// (environment, 65536 as the page), the supported pass through
// SUPPORT_ITEMS layers' worth (environment, 4 as the page).
// Usage: [WARM=1] node scripts/wasm_call_time.mjs [PASSES] [MODEL] [PKG_DIR] [ITEMS] [SETTINGS]
// (`bash scripts/build.sh` first; PKG_DIR: the wasm-bindgen output to time, www/pkg by default)
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
const importItems = Number(process.env.IMPORT_ITEMS || 65536);
const supportItems = Number(process.env.SUPPORT_ITEMS || 4);
const limit = Number(process.env.LIMIT || 10);
const core = await import(pathToFileURL(join(pkg, "dropslice.js")).href);
core.initSync({ module: readFileSync(join(pkg, "dropslice_bg.wasm")) });
// The CPU of this thread alone (Linux: its schedstat, ns), so that neither the machine's load nor
// the engine's compiling on its background threads counts: what a worker's call costs its
// thread. Elsewhere the process' CPU (which counts the background compiling too).
const ownThread = (() => {
  try {
    readFileSync("/proc/thread-self/schedstat", "utf8");
    return true;
  } catch {
    return false;
  }
})();
const cpuMs = ownThread
  ? () => Number(readFileSync("/proc/thread-self/schedstat", "utf8").split(" ")[0]) / 1e6
  : () => {
      const u = process.cpuUsage();
      return (u.user + u.system) / 1e3;
    };
const name = basename(model);
const bytes = readFileSync(model);
const job = { settings, parts: [{ file: name }] };

// WARM=1: first the warm-up a page's worker makes while it waits for the job worker's draft
// (www/worker/worker.ts `warmUp`: the sample part prepared and a lower layer sliced), so that
// the first pass' layers show what they cost once the layer path is compiled.
if (process.env.WARM === "1") {
  const { build } = await import("esbuild");
  const out = await build({ entryPoints: [join(repo, "www/core/sample.ts")], bundle: true, format: "esm", platform: "neutral", write: false, logLevel: "error" });
  const { sampleStl } = await import(`data:text/javascript;base64,${Buffer.from(out.outputFiles[0].text).toString("base64")}`);
  const t0 = cpuMs();
  const sample = sampleStl();
  const s = new core.Session(sample.bytes, sample.name, {});
  const i = Math.max(1, Math.floor(s.layer_count() / 4));
  s.layer_ahead(i - 1);
  s.slice_layer(i - 1).free();
  while (!s.layer_ahead(i));
  s.slice_layer(i).free();
  s.free();
  console.log(`warm-up (the sample part's layer, as a waiting worker makes it): ${(cpuMs() - t0).toFixed(1)} ms`);
}

for (let k = 0; k < passes; k++) {
  /** Every call of the pass: [kind, name, ms]. */
  const calls = [];
  /** `f()`, timed as a call of `kind` named `what` (or what `what()` says after the call). */
  const timed = (kind, what, f) => {
    const t0 = cpuMs();
    try {
      return f();
    } finally {
      const ms = cpuMs() - t0;
      calls.push([kind, typeof what === "function" ? what() : what, ms]);
    }
  };
  const models = new core.Models();
  if (typeof core.Models.begin_add_bytes === "function") {
    const a = timed("import", "Models.begin_add_bytes", () => core.Models.begin_add_bytes(bytes, name));
    for (let i = 0; !timed("import", `Adding.step ${i}`, () => a.step(importItems)); i++);
    timed("import", "Models.finish_add", () => models.finish_add(a));
  } else timed("import", "Models.add_bytes", () => models.add_bytes(bytes, name));

  let s;
  let draft = null;
  // a step named by the passes it worked in
  const stepName = (p, i) => () => `Preparing.step ${i}${typeof p.pass === "function" ? ` (${p.pass()})` : ""}`;
  if (typeof core.Session.begin_drafted === "function") {
    const p = timed("preparation", "Session.begin_drafted", () => core.Session.begin_drafted(models, job));
    for (let i = 0; ; i++) {
      const done = timed("preparation", stepName(p, i), () => p.step(items));
      draft ??= timed("preparation", "Preparing.take_draft", () => p.take_draft()) ?? null;
      if (done) break;
    }
    s = timed("preparation", "Session.from_preparation", () => core.Session.from_preparation(p));
  } else if (typeof core.Session.begin === "function") {
    const p = timed("preparation", "Session.begin", () => core.Session.begin(models, job));
    for (let i = 0; !timed("preparation", stepName(p, i), () => p.step(items)); i++);
    s = core.Session.from_preparation(p);
  } else s = timed("preparation", "Session.from_models", () => core.Session.from_models(models, job));

  const takeItems = Number(process.env.TAKE_ITEMS || 65536);
  /** Another worker's session of `bytes` (in short calls where the module has them). */
  const take = (bytes, isDraft) => {
    const one = isDraft ? "Session.from_draft" : "Session.from_prepared";
    if (typeof core.Session.begin_take !== "function") return timed("hand-off", one, () => core.Session[isDraft ? "from_draft" : "from_prepared"](bytes));
    const t = timed("hand-off", "Session.begin_take", () => core.Session.begin_take(bytes, isDraft));
    for (let i = 0; !timed("hand-off", `Taking.step ${i} (${isDraft ? "draft" : "prepared"})`, () => t.step(takeItems)); i++);
    return core.Session.from_taken(t);
  };
  if (draft) {
    const d = take(draft, true);
    const table = timed("hand-off", "Session.confirmation", () => s.confirmation());
    if (table) timed("hand-off", "Session.confirm", () => d.confirm(table));
    d.free();
  }
  let out;
  if (typeof s.begin_prepared === "function") {
    const w = timed("hand-off", "Session.begin_prepared", () => s.begin_prepared());
    for (let i = 0; !timed("hand-off", `Writing.step ${i}`, () => w.step(takeItems)); i++);
    out = w.take();
    w.free();
  } else out = timed("hand-off", "Session.prepared", () => s.prepared());
  take(out, false).free();
  if (typeof s.support_step === "function") for (let i = 0; !timed("supported pass", `Session.support_step ${i}`, () => s.support_step(supportItems)); i++);
  // As the page's worker does: the section and the overhang figure ahead, then the rest.
  for (let i = 0; i < s.layer_count(); i++) {
    for (let k = 0; !timed("layers", `layer_ahead ${i} (${k})`, () => s.layer_ahead(i)); k++);
    timed("layers", `slice_layer ${i}`, () => s.slice_layer(i)).free();
  }
  s.free();
  models.free();

  const kinds = [...new Set(calls.map((c) => c[0]))].map((kind) => {
    const of = calls.filter((c) => c[0] === kind);
    const longest = of.reduce((a, c) => (c[2] > a[2] ? c : a));
    const sum = of.reduce((a, c) => a + c[2], 0);
    return `${kind} ${sum.toFixed(0)} ms in ${of.length} calls (the longest ${longest[2].toFixed(1)} ms, ${longest[1]})`;
  });
  console.log(`pass ${k + 1}: ${kinds.join("; ")}`);
  const over = calls.filter((c) => c[2] > limit);
  console.log(`  calls over ${limit} ms (${over.length}): ${over.map((c) => `${c[1]} ${c[2].toFixed(1)}`).join(", ") || "none"}`);
}

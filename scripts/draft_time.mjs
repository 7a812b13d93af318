// When the page's other workers can start slicing (docs/performance.md, "The page"), in Node
// on one thread, CPU ms (process.cpuUsage, so that a loaded machine's waiting does not count):
// the job worker's preparation in short calls as the page runs it (`Session.begin_drafted`,
// `Preparing.step(16384)`), the CPU spent until its draft was handed out and until the job was
// made; the other worker's side of each hand-off: the draft taken (`Session.from_draft`) and
// confirmed (`confirmation`, `confirm`), against the prepared job written and taken
// (`prepared`, `from_prepared`). So the other worker starts after "draft + taken" instead of
// "prepared + written + taken". Then the layers (`slice_layer`, all of them) for scale. PASSES
// times from a module just loaded (the first pass runs while the engine still compiles).
// Usage: node scripts/draft_time.mjs [PASSES] [MODEL.stl] [PKG_DIR]   (`bash scripts/build.sh` first)
import { readFileSync } from "node:fs";
import { basename, dirname, join, resolve } from "node:path";
import { fileURLToPath, pathToFileURL } from "node:url";

const repo = resolve(dirname(fileURLToPath(import.meta.url)), "..");
const passes = Number(process.argv[2] ?? 2);
if (!Number.isInteger(passes) || passes < 1 || passes > 50) throw new Error(`expected 1 to 50 passes, got ${process.argv[2]}`);
const model = process.argv[3] || join(repo, "../shared/models/3DBenchy.stl");
const pkg = resolve(process.argv[4] || join(repo, "www/pkg"));
const core = await import(pathToFileURL(join(pkg, "dropslice.js")).href);
core.initSync({ module: readFileSync(join(pkg, "dropslice_bg.wasm")) });
const cpuMs = () => {
  const u = process.cpuUsage();
  return (u.user + u.system) / 1e3;
};
const name = basename(model);
const models = new core.Models();
models.add_bytes(readFileSync(model), name);
const job = { settings: {}, parts: [{ file: name }] };
const ms = (t) => `${t.toFixed(0)} ms`;
for (let k = 0; k < passes; k++) {
  const t0 = cpuMs();
  const p = core.Session.begin_drafted(models, job);
  let draft = null;
  let atDraft = 0;
  while (!p.step(16384)) {
    const d = p.take_draft();
    if (d) [draft, atDraft] = [d, cpuMs() - t0];
  }
  const d = p.take_draft();
  if (d) [draft, atDraft] = [d, cpuMs() - t0];
  const s = core.Session.from_preparation(p);
  const prepared = cpuMs() - t0;
  if (!draft) throw new Error("no draft was made");
  let t = cpuMs();
  const other = core.Session.from_draft(draft);
  const taken = cpuMs() - t;
  t = cpuMs();
  const table = s.confirmation();
  if (table) other.confirm(table);
  const confirmed = cpuMs() - t;
  other.free();
  t = cpuMs();
  const bytes = s.prepared();
  const written = cpuMs() - t;
  t = cpuMs();
  core.Session.from_prepared(bytes).free();
  const read = cpuMs() - t;
  const n = s.layer_count();
  t = cpuMs();
  for (let i = 0; i < n; i++) s.slice_layer(i).free();
  const layers = cpuMs() - t;
  s.free();
  const before = prepared + written + read;
  const after = atDraft + taken;
  console.log(
    `pass ${k + 1}: draft handed out after ${ms(atDraft)} of the preparation's ${ms(prepared)} (${((100 * atDraft) / prepared).toFixed(0)} %); ` +
      `draft taken ${ms(taken)}, ${table ? `confirmed ${ms(confirmed)}` : "NOT the job's draft"}; prepared job written ${ms(written)}, taken ${ms(read)}; ` +
      `the other worker starts after ${ms(after)} instead of ${ms(before)} (−${ms(before - after)}); all ${n} layers ${ms(layers)}`,
  );
}

// The page's workers' memory on a model (the 1M-facet torus by default), in Node: the
// module compiled once, two instances as the page's two workers. The job worker imports the
// file (`Models.add_bytes`), prepares the job in short calls and writes the hand-off's bytes
// (`Session.prepared`); the other worker takes them (`Session.from_prepared`). Then the same
// with a draft, as the page slices (fresh instances): the job worker prepares with
// `Session.begin_drafted` and hands out the draft as soon as it is made; the other worker
// takes it (`Session.from_draft`) and the job worker's confirmation
// (`Session.confirm`). Prints each worker's module memory (it never shrinks: the most it ever
// held) after each of these.
// Usage: node scripts/worker_memory.mjs [MODEL.stl] [PKG_DIR]   (`bash scripts/build.sh` first)
import { readFileSync } from "node:fs";
import { basename, dirname, join, resolve } from "node:path";
import { fileURLToPath, pathToFileURL } from "node:url";

const repo = resolve(dirname(fileURLToPath(import.meta.url)), "..");
const model = process.argv[2] || join(repo, "target/bench/models/torus_1000000.stl");
const pkg = resolve(process.argv[3] || join(repo, "www/pkg"));
const module = new WebAssembly.Module(readFileSync(join(pkg, "dropslice_bg.wasm")));
const glue = pathToFileURL(join(pkg, "dropslice.js")).href;
// two instances of the glue (each keeps its instance in module-level state)
const jobWorker = await import(`${glue}?job`);
const other = await import(`${glue}?other`);
const jobWorker2 = await import(`${glue}?job2`);
const other2 = await import(`${glue}?other2`);
const memJob = jobWorker.initSync({ module }).memory;
const memOther = other.initSync({ module }).memory;
const mb = (m) => `${(m.buffer.byteLength / 2 ** 20).toFixed(0)} MB`;
const name = basename(model);
const bytes = readFileSync(model);
const models = new jobWorker.Models();
models.add_bytes(bytes, name);
console.log(`job worker: file imported (${(bytes.length / 2 ** 20).toFixed(0)} MB file): ${mb(memJob)}`);
const p = jobWorker.Session.begin(models, { settings: {}, parts: [{ file: name }] });
while (!(p.step.length > 0 ? p.step(16384) : p.step()));
const s = jobWorker.Session.from_preparation(p);
console.log(`job worker: job prepared: ${mb(memJob)}`);
const prepared = s.prepared();
console.log(`job worker: hand-off written (${(prepared.length / 2 ** 20).toFixed(0)} MB): ${mb(memJob)}`);
const copy = prepared.slice(); // as the page's job worker makes one per other worker
const taken = other.Session.from_prepared(copy);
console.log(`other worker: hand-off taken (${taken.layer_count()} layers): ${mb(memOther)}`);

// with a draft
const memJob2 = jobWorker2.initSync({ module }).memory;
const memOther2 = other2.initSync({ module }).memory;
const models2 = new jobWorker2.Models();
models2.add_bytes(bytes, name);
const p2 = jobWorker2.Session.begin_drafted(models2, { settings: {}, parts: [{ file: name }] });
let draft = null;
let taken2 = null;
for (let done = false; !done; ) {
  done = p2.step(16384);
  const d = p2.take_draft();
  if (d) {
    draft = d;
    console.log(`job worker (draft): draft written (${(d.length / 2 ** 20).toFixed(0)} MB): ${mb(memJob2)}`);
    taken2 = other2.Session.from_draft(d.slice());
    console.log(`other worker (draft): draft taken (${taken2.layer_count()} layers): ${mb(memOther2)}`);
  }
}
const s2 = jobWorker2.Session.from_preparation(p2);
console.log(`job worker (draft): job prepared: ${mb(memJob2)}`);
const table = s2.confirmation();
if (!draft || !table) throw new Error("no draft, or the job is not its draft's");
taken2.confirm(table.slice());
console.log(`other worker (draft): confirmed (${table.length} B): ${mb(memOther2)}`);

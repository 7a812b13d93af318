// The page's workers' memory on a model (the 1M-facet torus by default), in Node: the
// module compiled once, two instances as the page's two workers. The job worker imports the
// file (`Models.add_bytes`), prepares the job in short calls and writes the hand-off's bytes
// (`Session.prepared`); the other worker takes them (`Session.from_prepared`). Prints each
// worker's module memory (it never shrinks: the most it ever held) after each of these.
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

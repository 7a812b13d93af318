// Unit tests of the page's pure modules (G-code reader, preview links, settings parsing,
// sample part), bundled from www/core and www/worker with esbuild and run in Node.
import { after, before, test } from "node:test";
import assert from "node:assert/strict";
import { mkdtempSync, readFileSync, rmSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { pathToFileURL } from "node:url";
import { build } from "esbuild";
import { repo } from "./helpers.mjs";

const out = mkdtempSync(join(tmpdir(), "dropslice-units-"));
let gcode, share, form, sample;
/** The core's job schema: a link's parts are checked against it. */
let jobSchema;

before(async () => {
  const names = ["worker/gcode", "core/share", "core/settings", "core/sample"];
  await build({
    entryPoints: names.map((n) => join(repo, "www", `${n}.ts`)),
    bundle: true,
    format: "esm",
    platform: "neutral",
    outdir: out,
    logLevel: "error",
  });
  [gcode, share, form, sample] = await Promise.all(names.map((n) => import(pathToFileURL(join(out, `${n}.js`)).href)));
  // the G-code reader is the core's (built into www/pkg by the page build)
  await gcode.loadCore(readFileSync(join(repo, "www", "pkg", "dropslice_bg.wasm")));
  const core = await import(pathToFileURL(join(repo, "www", "pkg", "dropslice.js")).href);
  await core.default({ module_or_path: readFileSync(join(repo, "www", "pkg", "dropslice_bg.wasm")) });
  jobSchema = core.job_schema();
});

after(() => rmSync(out, { recursive: true, force: true }));

const HEADER = "; dropslice test\n; layer_height = 0.2 (mm)\n; droplet_aspect = 1.04\n; end of header\n";

function read(text) {
  const layers = [];
  const r = new gcode.GcodeReader((l) => layers.push(l));
  for (const line of text.split("\n")) r.line(line);
  r.finish();
  return { layers, reader: r };
}

test("G-code reader: G25 lines expand to droplets every B, layers split on Z", () => {
  const B = 0.2 * 1.04;
  const { layers, reader } = read(
    HEADER +
      "G26 X1.0000 Y1.0000 Z0.2000\nG26 X1.2080 Y1.0000 Z0.2000\n" +
      `G01 X0.0000 Y0.0000 Z0.2000\nG25 X${(10 * B).toFixed(4)} Y0.0000 Z0.2000\n` +
      "G26 X5.0000 Y5.0000 Z0.4000\n",
  );
  assert.equal(reader.dropletWidth, B);
  assert.equal(layers.length, 2);
  assert.deepEqual(layers[0].counts, { outer: 2, inner: 0, fill: 11, support: 0, unit1: 0 });
  assert.equal(layers[0].roles.length, 13);
  assert.ok(Math.abs(layers[0].droplets[2 * 12] - 10 * B) < 1e-4, "last droplet at the line's end");
  assert.ok(Math.abs(layers[0].droplets[2 * 3] - B) < 1e-6, "second droplet one B along");
  assert.equal(layers[0].travel.length, 4);
  assert.equal(layers[1].z, 0.4);
  assert.equal(layers[1].counts.outer, 1);
});

test("G-code reader: after T1 droplets are unit 1's, every B₁ along a G25 line", () => {
  const B1 = 0.2 * 2.0;
  const { layers } = read(
    "; layer_height = 0.2\n; droplet_aspect = 1.0\n; unit1_droplet_aspect = 2.0\n" +
      "G26 X0.0000 Y0.0000 Z0.2000\nT1\nG01 X0.0000 Y1.0000 Z0.2000\n" +
      `G25 X${(3 * B1).toFixed(4)} Y1.0000 Z0.2000\nT0\nG26 X0.0000 Y2.0000 Z0.2000\n`,
  );
  assert.deepEqual([...layers[0].units], [0, 1, 1, 1, 1, 0]);
  assert.equal(layers[0].counts.unit1, 4);
  assert.ok(Math.abs(layers[0].droplets[2 * 2] - B1) < 1e-4, "unit 1's droplets B₁ apart");
});

test("G-code reader: refuses files it cannot understand", () => {
  assert.throws(() => read("G26 X1 Y1 Z0.2\n"), /droplet size/);
  assert.throws(() => read(HEADER + "M104 S200\n"), /G-code for another kind of printer \(it has M104\)/);
  assert.throws(() => read(HEADER + "hello\n"), /not a G01, G25 or G26/);
  assert.throws(() => read(HEADER + "G26 X1 Yabc Z0.2\n"), /bad number/);
  assert.throws(() => read(HEADER + "G26 X1 Q2 Z0.2\n"), /unknown word/);
  assert.throws(() => read(HEADER), /no G01\/G25\/G26/);
});

test("preview links: base64url and deflate round trips, hash of bytes", async () => {
  const bytes = new Uint8Array(70_000).map((_, i) => (i * 31) % 256);
  assert.deepEqual(share.fromBase64Url(share.toBase64Url(bytes)), bytes);
  assert.doesNotMatch(share.toBase64Url(bytes), /[+/=]/);
  assert.deepEqual(await share.inflate(await share.deflate(bytes)), bytes);
  assert.equal(
    await share.sha256Hex(new TextEncoder().encode("abc")),
    "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad",
  );
});

test("preview links: embedded when small, hash only when big", async () => {
  const state = { settings: { contours: 3 }, layer: 7, view: { scale: 12, cx: 1, cy: 2 }, name: "p.stl", sha256: "ab" };
  const small = new Uint8Array(1000).fill(7);
  const a = await share.makeLink("http://x/#old", state, new Blob([small]));
  assert.ok(a.embedded && a.url.startsWith("http://x/#p="));
  const back = await share.readLink(a.url.slice(a.url.indexOf("#")), jobSchema);
  assert.deepEqual(back.state, state);
  assert.deepEqual(back.model, small);
  // random bytes do not compress: 300 KB stays above the 256 KB limit
  const big = new Uint8Array(300_000);
  for (let i = 0; i < big.length; i += 65536) crypto.getRandomValues(big.subarray(i, i + 65536));
  const b = await share.makeLink("http://x/", state, new Blob([big]));
  assert.equal(b.embedded, false);
  assert.doesNotMatch(b.url, /&m=/);
  assert.equal((await share.readLink(b.url.slice(b.url.indexOf("#")), jobSchema)).model, null);
  assert.equal(await share.readLink("#", jobSchema), null);
  await assert.rejects(share.readLink("#p=AAAA", jobSchema));
});

test("settings: relaxed input becomes strict values, with messages", () => {
  const spec = { name: "layer_height", kind: "number", unit: "mm", min: 0, max: 5, min_exclusive: true, choices: [], group: "g", description: "", default: 0.2 };
  assert.deepEqual(form.parse(spec, " 0,25 "), { value: 0.25 });
  assert.match(form.parse(spec, "0").error, /greater than 0 mm/);
  assert.match(form.parse(spec, "6").error, /at most 5 mm/);
  assert.match(form.parse(spec, "").error, /needed/);
  assert.match(form.parse(spec, "1e").error, /not a number/);
  const int = { ...spec, kind: "integer", min_exclusive: false, unit: "" };
  assert.match(form.parse(int, "2.5").error, /whole number/);
  assert.deepEqual(form.parse(int, "3"), { value: 3 });
  const en = { ...spec, kind: "enum", choices: ["a", "b"] };
  assert.deepEqual(form.parse(en, "b"), { value: "b" });
  assert.ok(form.parse(en, "c").error);
  assert.deepEqual(form.parse({ ...spec, kind: "bool" }, true), { value: true });
});

test("sample part: a closed binary STL (every edge shared by exactly two facets, opposite ways)", () => {
  const { bytes, name } = sample.sampleStl();
  assert.match(name, /\.stl$/);
  const dv = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  const n = dv.getUint32(80, true);
  assert.equal(bytes.length, 84 + 50 * n);
  const edges = new Map();
  const key = (o) => [0, 4, 8].map((k) => dv.getFloat32(o + k, true)).join(",");
  for (let f = 0; f < n; f++) {
    const o = 84 + 50 * f + 12;
    const v = [key(o), key(o + 12), key(o + 24)];
    for (let k = 0; k < 3; k++) {
      const e = `${v[k]}|${v[(k + 1) % 3]}`;
      edges.set(e, (edges.get(e) ?? 0) + 1);
    }
  }
  for (const [e, count] of edges) {
    const [a, b] = e.split("|");
    assert.equal(count, 1, `edge ${e} used ${count} times in one direction`);
    assert.equal(edges.get(`${b}|${a}`), 1, `edge ${e} has no opposite`);
  }
});

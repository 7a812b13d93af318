// Untrusted input cannot freeze the page: crafted preview links (view, layer, settings, damaged
// base64, deflate bombs), ?workers=N, and crafted .gco files (huge or non-finite coordinates,
// absurd droplet sizes, lines expanding to too many droplets). For each: the page keeps
// answering (page.evaluate within 2 s, polled), the view and layer stay finite and in range,
// what was refused is named in the banner, and the Content-Security-Policy is never violated.
import { test } from "node:test";
import assert from "node:assert/strict";
import { deflateRawSync } from "node:zlib";
import { answers, b64url, countPixels, cube, cubeSha, openPage, settleAnswering as settle, startForTests, status } from "./helpers.mjs";

const env = startForTests();

/** A fresh page that records page errors, console errors and CSP violations. */
const open = (path = "") => openPage(env.browser, env.url + path, { width: 1280, height: 800, csp: true });

const banner = async (page) => ((await page.isVisible("#banner")) ? await page.locator("#banner").innerText() : "");

/** The page is sane: view finite and within the renderer's limits, layer an integer in range,
 *  no "NaN" in the layer label, no page error, no CSP violation. */
async function sane(page, errors) {
  await answers(page, 4);
  const s = await status(page);
  const v = s.view;
  assert.ok([v.scale, v.cx, v.cy].every(Number.isFinite), `view ${JSON.stringify(v)}`);
  assert.ok(v.scale >= 0.05 && v.scale <= 5000, `scale ${v.scale}`);
  assert.ok(Math.abs(v.cx) <= 1e5 && Math.abs(v.cy) <= 1e5, `centre ${v.cx}, ${v.cy}`);
  assert.ok(Number.isInteger(s.layer) && s.layer >= 0 && (s.layers === 0 || s.layer < s.layers), `layer ${s.layer} of ${s.layers}`);
  assert.doesNotMatch(await page.locator("#layer-label").innerText(), /NaN|undefined|Infinity/);
  assert.doesNotMatch(await page.locator("#zoom").innerText(), /NaN|Infinity/);
  assert.deepEqual(await page.evaluate(() => window.__csp), [], "CSP violations");
  assert.deepEqual(errors, [], "page errors");
  return s;
}

/** The state of a link as raw JSON text, so that it can hold 1e400 (Infinity), strings and
 *  other things JSON.stringify would not write. `over` replaces fields (undefined drops one). */
function stateText(over = {}) {
  const parts = {
    settings: "{}",
    layer: "10",
    view: '{"scale":12,"cx":1,"cy":2}',
    name: '"cube.stl"',
    sha256: JSON.stringify(cubeSha),
    ...over,
  };
  return `{${Object.entries(parts).filter(([, v]) => v !== undefined).map(([k, v]) => `"${k}":${v}`).join(",")}}`;
}

/** The job files of a link of the cube (`files` as JSON text). */
function jobFiles(name = "cube.stl") {
  return JSON.stringify([{ name, sha256: cubeSha, bytes: cube.length }]);
}

/** A link's fragment: the state deflated, the cube embedded (unless `m` is given). */
function link(state, { p, m } = {}) {
  const pp = p ?? b64url(deflateRawSync(Buffer.from(state)));
  const mm = m === undefined ? b64url(deflateRawSync(cube)) : m;
  return `#p=${pp}${mm ? `&m=${mm}` : ""}`;
}

test("the page loads under its CSP, slices the sample, downloads, shares, and never violates the policy", async () => {
  const { page, context, errors } = await open();
  const s = await settle(page);
  assert.equal(s.state, "done");
  assert.equal(s.name, "sample-block-with-boss.stl");
  assert.ok(s.droplets > 0);
  const csp = await page.getAttribute('meta[http-equiv="Content-Security-Policy"]', "content");
  assert.match(csp, /script-src 'self' 'wasm-unsafe-eval'/);
  const html = await (await page.request.get(`${env.url}index.html`)).text();
  assert.doesNotMatch(html, /\sstyle=|\son[a-z]+=|<script(?![^>]*\ssrc=)|<style/i, "no inline style, handler or script in the markup");
  // the legend keeps its colours from the stylesheet
  const bg = await page.evaluate(() => getComputedStyle(document.querySelector("#legend i.role-0")).backgroundColor);
  assert.equal(bg, "rgb(217, 72, 15)");
  await page.waitForTimeout(100);
  assert.ok((await countPixels(page, "Math.max(r, g, b) - Math.min(r, g, b) > 60")) > 1000, "droplets are drawn");
  const [download] = await Promise.all([page.waitForEvent("download"), page.click("#btn-download")]);
  assert.equal(download.suggestedFilename(), "sample-block-with-boss.gco");
  await page.click("#btn-share");
  await page.waitForSelector("#share-dialog[open]");
  await page.click("#share-dialog button"); // a <form method="dialog">: allowed by form-action 'none'
  await page.waitForSelector("#share-dialog:not([open])", { state: "attached" });
  // Enter in the form does not submit it
  await page.focus("#set-contours");
  await page.keyboard.press("Enter");
  await settle(page);
  assert.equal(new URL(page.url()).pathname, "/");
  await sane(page, errors);
  await context.close();
});

// [what, state text or fragment options, banner expected (RegExp) or null for none, extra check]
const LINKS = [
  ["a valid link", stateText(), null, (s) => {
    assert.equal(s.layer, 10);
    assert.deepEqual(s.view, { scale: 12, cx: 1, cy: 2 });
  }],
  ["view centre 1e20", stateText({ view: '{"scale":10,"cx":1e20,"cy":1e20}' }), /view \(centre 1e\+20, 1e\+20 mm is beyond ±100,000 mm: the part is fitted instead\)/],
  ["view centre -1e300", stateText({ view: '{"scale":10,"cx":-1e300,"cy":0}' }), /view \(centre -1e\+300/],
  ["view centre +Infinity", stateText({ view: '{"scale":10,"cx":1e400,"cy":0}' }), /view \(not three finite numbers/],
  ["view centre -Infinity", stateText({ view: '{"scale":10,"cx":0,"cy":-1e400}' }), /view \(not three finite numbers/],
  ["view centre NaN (null)", stateText({ view: '{"scale":10,"cx":null,"cy":0}' }), /view \(not three finite/],
  ["view centre a string", stateText({ view: '{"scale":10,"cx":"NaN","cy":0}' }), /view \(not three finite/],
  ["view scale 1e300", stateText({ view: '{"scale":1e300,"cx":0,"cy":0}' }), /zoom \(1e\+300 px\/mm, limited to 5000 px\/mm\)/, (s) => assert.equal(s.view.scale, 5000)],
  ["view scale 1e20", stateText({ view: '{"scale":1e20,"cx":0,"cy":0}' }), /zoom \(1e\+20 px\/mm, limited to 5000/],
  ["view scale +Infinity", stateText({ view: '{"scale":1e400,"cx":0,"cy":0}' }), /view \(not three finite/],
  ["view scale -Infinity", stateText({ view: '{"scale":-1e400,"cx":0,"cy":0}' }), /view \(not three finite/],
  ["view scale NaN (null)", stateText({ view: '{"scale":null,"cx":0,"cy":0}' }), /view \(not three finite/],
  ["view scale negative", stateText({ view: '{"scale":-3,"cx":0,"cy":0}' }), /view \(zoom -3 px\/mm is not positive/],
  ["view scale 0", stateText({ view: '{"scale":0,"cx":0,"cy":0}' }), /view \(zoom 0 px\/mm is not positive/],
  ["view scale tiny", stateText({ view: '{"scale":1e-300,"cx":0,"cy":0}' }), /zoom \(1e-300 px\/mm, limited to 0.05/],
  ["view not an object", stateText({ view: '"far away"' }), /view \(not three finite/],
  ["layer NaN (null)", stateText({ layer: "null" }), /layer \(null is not a layer number: a default layer is shown\)/],
  ["layer a string", stateText({ layer: '"12"' }), /layer \("12" is not a layer number: a default layer is shown\)/],
  ["layer -1", stateText({ layer: "-1" }), null, (s) => assert.equal(s.layer, 0)],
  ["layer 1e9", stateText({ layer: "1e9" }), null, (s) => assert.equal(s.layer, s.layers - 1)],
  ["layer Infinity", stateText({ layer: "1e400" }), /layer \(Infinity is not a layer number: a default layer is shown\)/],
  ["layer 2.6", stateText({ layer: "2.6" }), null, (s) => assert.equal(s.layer, 3)],
  ["settings of wrong types", stateText({ settings: '{"layer_height":"abc","contours":{},"close_loops":1,"contour_order":5,"hatch_angle":[45],"fill_density":1e400}' }),
    /partly damaged: its setting/,
    async (s, text) => {
      for (const part of [/setting layer_height \("abc" is not a number: the default is used\)/, /setting contours \(an object is not/, /setting close_loops \(1 is not yes or no/, /setting contour_order \(5 is not one of the choices/, /setting hatch_angle \(a list is not/, /setting fill_density \(Infinity is not a finite number/]) {
        assert.match(text, part);
      }
      assert.ok(s.droplets > 0);
    }],
  ["a setting named __proto__", stateText({ settings: '{"__proto__":0.3,"constructor":1}' }), /a setting named "__proto__"/],
  ["settings not an object", stateText({ settings: "[1,2]" }), /too large or damaged: its settings are not a list of settings/, (s) => assert.equal(s.name, "sample-block-with-boss.stl")],
  ["sha256 not hex", stateText({ sha256: '"zz"' }), /too large or damaged: its model's SHA-256 is missing or not hexadecimal digits \(at most 64\)/],
  ["sha256 too long", stateText({ sha256: JSON.stringify("a".repeat(65)) }), /too large or damaged: its model's SHA-256 is missing or not hexadecimal digits/],
  ["sha256 a number", stateText({ sha256: "5" }), /too large or damaged: its model's SHA-256/],
  ["name missing", stateText({ name: undefined }), /too large or damaged: its model's name is missing/],
  ["a long name", stateText({ name: JSON.stringify("n".repeat(5000)) }), null, (s) => assert.ok(s.name.length < 300)],
  ["state not JSON", "{not json", /too large or damaged: its state is not readable/],
  ["state an array", "[1,2,3]", /too large or damaged: its state is not a preview's state/],
  ["damaged base64 (characters)", { p: "ab$cd!!" }, /too large or damaged: its state holds characters/],
  ["damaged base64 (length)", { p: "abcde" }, /too large or damaged: its state holds characters/],
  ["not deflate", { p: b64url(Buffer.from("hello, this is not deflate data at all")) }, /too large or damaged: its state is not valid compressed data/],
  ["cut short", { p: b64url(deflateRawSync(Buffer.from(stateText())).subarray(0, 20)) }, /too large or damaged: its state is not valid compressed data/],
  ["state too long before decoding", { p: "A".repeat(100_000) }, /too large or damaged: its state is 100,000 characters long/],
  ["a deflate bomb in p=", { p: b64url(deflateRawSync(Buffer.alloc(50e6, 32))) }, /too large or damaged: its state unpacks to more than 64 KB/],
  ["a deflate bomb in m=", { state: stateText(), m: b64url(deflateRawSync(Buffer.alloc(200e6))) }, /too large or damaged: its model unpacks to more than 64 MB/, (s) => assert.equal(s.state, "idle")],
  ["a damaged model", { state: stateText(), m: b64url(Buffer.from("not deflate")) }, /too large or damaged: its model is not valid compressed data/],
  // a build job's link: its files and parts are bounded and checked like the rest
  ["a job link", stateText({ files: jobFiles(), parts: '[{"file":"cube.stl","rotate_z":90,"copies":2}]' }), null, (s) => assert.ok(s.droplets > 0)],
  ["a job of 257 parts", stateText({ files: jobFiles(), parts: JSON.stringify(Array.from({ length: 257 }, () => ({ file: "cube.stl" }))) }), /too large or damaged: its job has 257 parts; at most 256 are accepted/],
  ["a job file name of 300 characters", stateText({ files: jobFiles("x".repeat(300)), parts: '[{"file":"cube.stl"}]' }), /too large or damaged: its job's file 1 has no name of 1 … 255 characters/],
  ["a job part naming no file", stateText({ files: jobFiles(), parts: '[{"file":"other.stl"}]' }), /too large or damaged: its part 1 names no file of the link/],
  ["a job file of 1e400 bytes", stateText({ files: `[{"name":"cube.stl","sha256":"${cubeSha}","bytes":1e400}]`, parts: '[{"file":"cube.stl"}]' }), /too large or damaged: its job's file "cube.stl" has no size/],
  ["job part numbers out of range", stateText({ files: jobFiles(), parts: '[{"file":"cube.stl","rotate_z":1e400,"scale_x":-2,"copies":2.5,"place_x":3,"evil":1}]' }),
    /partly damaged: its part 1's rotate_z \(Infinity is not a number in -360 … 360: the default is used\)/,
    async (s, text) => {
      for (const part of [/part 1's scale_x \(-2 is not a number in \(0 … 1000/, /part 1's copies \(2\.5 is not a whole number in 1 … 100/, /part 1's evil \(not a part's setting\)/, /part 1's place \(x and y go together/]) assert.match(text, part);
      assert.ok(s.droplets > 0);
    }],
  ["a model that does not match", { state: stateText({ sha256: JSON.stringify("0".repeat(64)) }) }, /too large or damaged: its model does not match the SHA-256 it carries/, (s) => assert.equal(s.state, "idle")],
];

for (const [what, spec, expected, check] of LINKS) {
  test(`link: ${what}`, async () => {
    const fragment = typeof spec === "string" ? link(spec) : spec.state ? link(spec.state, { m: spec.m }) : link("", { p: spec.p, m: null });
    const t0 = Date.now();
    const { page, context, errors } = await open(fragment);
    const s0 = await settle(page);
    const s = await sane(page, errors);
    const text = await banner(page);
    if (expected) assert.match(text, expected, `banner: ${text}`);
    else assert.equal(text, "", "no banner");
    if (s0.state === "done") assert.ok(s.droplets > 0);
    await check?.(s, text);
    const seconds = (Date.now() - t0) / 1000;
    assert.ok(seconds < 30, `${what}: ${seconds} s`);
    await context.close();
  });
}

test("the renderer keeps any view in range on its own and draws it at once", async () => {
  const { page, context, errors } = await open();
  await settle(page);
  for (const v of [{ scale: 1e300, cx: 1e20, cy: -1e20 }, { scale: NaN, cx: NaN, cy: NaN }, { scale: -1, cx: Infinity, cy: -Infinity }, { scale: 1e-300, cx: 1e5, cy: 1e5 }]) {
    const ms = await page.evaluate((v) => {
      window.dropslice.setView(v);
      const t0 = performance.now();
      window.dropslice.redraw();
      return performance.now() - t0;
    }, v);
    assert.ok(ms < 500, `draw took ${ms} ms`);
    await sane(page, errors);
  }
  // wheel and drag at the limits stay in range
  const box = await page.locator("#view").boundingBox();
  await page.mouse.move(box.x + 10, box.y + 10);
  for (let i = 0; i < 30; i++) await page.mouse.wheel(0, -5000);
  for (let i = 0; i < 30; i++) await page.mouse.wheel(0, 5000);
  await sane(page, errors);
  await context.close();
});

test("?workers=N is clamped to 1 … min(cores, 8) (at least 4 allowed); NaN gives the default (one per core, at most 8)", async () => {
  for (const [q, want] of [["16", (n, cores) => n === Math.min(8, Math.max(4, cores))], ["1000000", (n) => n <= 8], ["NaN", (n, cores) => n === Math.max(1, Math.min(cores, 8))], ["-3", (n) => n === 1], ["0", (n) => n === 1], ["2.4", (n) => n === 2], ["abc", (n, cores) => n === Math.max(1, Math.min(cores, 8))]]) {
    const { page, context, errors } = await open(`?workers=${q}`);
    const s = await settle(page);
    assert.equal(s.state, "done");
    const cores = await page.evaluate(() => navigator.hardwareConcurrency);
    assert.ok(want(s.workers, cores), `?workers=${q}: ${s.workers} workers on ${cores} cores`);
    await sane(page, errors);
    await context.close();
  }
});

const HEADER = "; dropslice test\n; layer_height = 0.2 (mm)\n; droplet_aspect = 1.04\n";

// [what, text, banner expected]
const GCO = [
  ["a huge coordinate", `${HEADER}G26 X0 Y0\nG26 X1e20 Y1e20\n`, /line 5: the coordinate "X1e20" is too far out: this viewer reads coordinates up to ±100,000 mm/],
  ["a huge Z", `${HEADER}G01 X0 Y0 Z1e6\n`, /line 4: the coordinate "Z1e6" is too far out/],
  ["NaN", `${HEADER}G26 XNaN Y0\n`, /line 4: bad number in "XNaN"/],
  ["Infinity", `${HEADER}G01 X0 Y-Infinity\n`, /line 4: bad number in "Y-Infinity"/],
  ["an empty number", `${HEADER}G26 X Y0\n`, /line 4: bad number in "X"/],
  ["a 1e-300 layer height", "; layer_height = 1e-300\nG01 X0 Y0 Z0.1\nG25 X1\n", /line 1: the header's layer_height = 1e-300 is out of range: it must be at least 0.0001 and at most 5 mm/],
  ["a layer height out of range", "; layer_height = 1e300\nG26 X0 Y0\n", /line 1: the header's layer_height = 1e300 is out of range: it must be at least 0.0001 and at most 5 mm/],
  ["a droplet aspect of 0", "; layer_height = 0.2\n; droplet_aspect = 0\nG26 X0 Y0\n", /line 2: the header's droplet_aspect = 0 is out of range/],
  ["a layer height that is not a number", "; layer_height = NaN\nG26 X0 Y0\n", /line 1: the header's layer_height = NaN is out of range/],
  ["a huge G25", `${HEADER}G01 X0 Y0 Z0.2\nG25 X20000000\n`, /line 5: the coordinate "X20000000" is too far out/],
  ["a G25 with a tiny droplet", "; layer_height = 0.0001\n; droplet_aspect = 0.001\nG01 X0 Y0 Z0.2\nG25 X100000 Y100000\n", /line 4: a G25 of 141421 mm would expand to [\d,]+ million droplets \(one every 1e-7 mm\)/],
  ["G25 lines past the droplet cap", `${HEADER}G01 X-100000 Y0 Z0.2\n${"G25 X100000 Y0\nG25 X-100000 Y0\n".repeat(30)}`, /line \d+: the file holds more than 50 million droplets, the most this viewer expands/],
  ["a line of 2 MB", `${HEADER}; ${"x".repeat(2 * 2 ** 20)}`, /is longer than 1,048,576 characters/],
  ["a filament printer's G-code", ";FLAVOR:Marlin\nM140 S60\nM104 S200\nG28\nG1 X10 Y10 Z0.3 E1.2\n", /line 2: this is G-code for another kind of printer \(it has M140, M104, G28, G1 … E…\): dropslice reads the droplet printer's code/],
];

test(".gco files: refused with the line and the reason; the page keeps answering and reads a good file after", async () => {
  const { page, context, errors } = await open();
  await settle(page);
  for (const [what, text, expected] of GCO) {
    const t0 = Date.now();
    await page.evaluate(() => (document.body.dataset.state = "picking"));
    await page.setInputFiles("#file-input", { name: `${what.replace(/\W+/g, "-")}.gco`, mimeType: "text/plain", buffer: Buffer.from(text) });
    const s = await settle(page, 120_000);
    assert.equal(s.state, "error", `${what}: ${JSON.stringify(s)}`);
    const b = await banner(page);
    assert.match(b, /cannot read the G-code file/i, what);
    assert.match(b, expected, `${what}: ${b}`);
    await sane(page, errors);
    console.log(`# ${what}: refused in ${((Date.now() - t0) / 1000).toFixed(1)} s`);
  }
  // a good file still opens
  const good = `${HEADER}G01 X0 Y0 Z0.2\nG25 X10 Y0\nG26 X10 Y1\nG01 X0 Y0 Z0.4\nG25 X0 Y10\n`;
  await page.evaluate(() => (document.body.dataset.state = "picking"));
  await page.setInputFiles("#file-input", { name: "good.gco", mimeType: "text/plain", buffer: Buffer.from(good) });
  const s = await settle(page);
  assert.equal(s.state, "done", await banner(page));
  assert.equal(s.layers, 2);
  assert.equal(s.droplets, Math.floor(10 / 0.208 + 1e-9) + 1 + 1 + Math.floor(10 / 0.208 + 1e-9) + 1);
  assert.equal(await banner(page), "");
  await sane(page, errors);
  await context.close();
});

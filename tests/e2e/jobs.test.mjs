// Build jobs in the page (www/core/job.ts, flows/job.ts, views/parts.ts, views/view3d/,
// flows/open.ts, core/share.ts): several files become one job, the core lays it out, the 3D
// view draws and moves its parts, job files and preview links carry it. G-code is checked
// against the core's layout (every droplet inside an instance's box) and against the page's
// own earlier output.
import { after, before, test } from "node:test";
import assert from "node:assert/strict";
import { mkdtempSync, readFileSync, writeFileSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { boxStl, clientPoint3d, downloadText, open3d, openLinkAskingForFile, openPage, parseGcode, pick, pixels3d, shared, shareLink, startWithPage, stop, torusStl, view3dReady, waitDone } from "./helpers.mjs";

let env;
let main;
const tmp = mkdtempSync(join(tmpdir(), "dropslice-jobs-"));
const model = (f) => join(shared, "models", f);
const cube = model("cube_20mm_ascii.stl");
const idler = model("extruder_idler_quads.obj");
const benchy = model("3DBenchy.stl");

before(async () => ({ env, main } = await startWithPage({ settle: true })));

after(() => stop(env, tmp));

const job = (page) => page.evaluate(() => window.dropslice.job());

/** Droplet centres of a .gco: every G26 and both ends of every G25 line. */
function droplets(text) {
  const out = [];
  let x = NaN;
  let y = NaN;
  for (const c of parseGcode(text)) {
    if (c.code === "G25") out.push([x, y], [c.x, c.y]);
    if (c.code === "G26") out.push([c.x, c.y]);
    if (!Number.isNaN(c.x)) x = c.x;
    if (!Number.isNaN(c.y)) y = c.y;
  }
  return out.filter(([a, b]) => Number.isFinite(a) && Number.isFinite(b));
}

const commands = (text) => parseGcode(text).map((c) => `${c.code} ${c.x} ${c.y} ${c.z}`);

let twoPartGcode = "";

test("two files opened at once: one job, both names shown, the G-code's droplets in the layout's two boxes", async () => {
  const { page, errors } = main;
  await pick(page, [cube, idler]);
  const s = await waitDone(page);
  assert.equal(s.name, "cube_20mm_ascii.stl + 1 more");
  const names = await page.locator(".part-item .part-name").allInnerTexts();
  assert.deepEqual(names, ["cube_20mm_ascii.stl", "extruder_idler_quads.obj"]);
  const stats = await page.locator("#stat-parts").innerText();
  assert.match(stats, /cube_20mm_ascii/);
  assert.match(stats, /extruder_idler_quads/);
  // several instances: the 3D tab is shown first
  await view3dReady(page);
  assert.equal(await page.isVisible("#view3d canvas"), true);

  const j = await job(page);
  assert.equal(j.layout.instances.length, 2);
  const text = await downloadText(page);
  twoPartGcode = text;
  assert.equal(text.split("\n").filter((l) => /^; part \d+ = /.test(l)).length, 2, "two part lines in the header");
  // every droplet lies in one instance's box (the core's layout), and both boxes have droplets
  const boxes = j.layout.instances.map((i) => ({ min: i.min, max: i.max, n: 0 }));
  const B = 0.2 * 1.04;
  const outside = [];
  for (const [x, y] of droplets(text)) {
    const box = boxes.find((b) => x >= b.min[0] - B && x <= b.max[0] + B && y >= b.min[1] - B && y <= b.max[1] + B);
    if (box) box.n++;
    else outside.push([x, y]);
  }
  assert.deepEqual(outside.slice(0, 5), [], `${outside.length} droplets outside the layout's boxes`);
  for (const b of boxes) assert.ok(b.n > 1000, `droplets in a box: ${b.n}`);
  // the arrangement keeps part_spacing (5 mm) between the boxes
  const [a, b] = boxes;
  const gap = Math.max(b.min[0] - a.max[0], a.min[0] - b.max[0], b.min[1] - a.max[1], a.min[1] - b.max[1]);
  assert.ok(gap >= 5 - 1e-6, `gap ${gap}`);
  assert.deepEqual(errors, []);
});

test("the 3D view draws both parts, each where the layout puts it", async () => {
  const { page } = main;
  const state = await open3d(page);
  assert.deepEqual(state.parts.sort(), ["0:0", "1:0"]);
  const seen = [];
  for (const k of [1, 2]) {
    await page.click(`.part-item:nth-child(${k})`);
    const px = await pixels3d(page);
    assert.ok(px.selected.n > 500, `selected part ${k}: ${px.selected.n} pixels`);
    assert.ok(px.part.n > 500, `the other part: ${px.part.n} pixels`);
    seen.push(px.selected);
  }
  assert.ok(Math.hypot(seen[0].x - seen[1].x, seen[0].y - seen[1].y) > 40, `two places: ${JSON.stringify(seen)}`);
});

test("dragging a part in 3D places it: the core lays the job out again", async () => {
  const { page } = main;
  await page.click(".part-item:nth-child(1)");
  const before = await job(page);
  assert.equal(before.parts[0].place_x, undefined, "arranged at first");
  const px = await pixels3d(page);
  assert.ok(px.selected.inner, "a pixel of the part to grab");
  const from = await clientPoint3d(page, px.selected.inner.x + 0.5, px.selected.inner.y + 0.5);
  await page.mouse.move(from.x, from.y);
  await page.mouse.down();
  await page.mouse.move(from.x + 60, from.y - 30, { steps: 8 });
  await page.mouse.up();
  await page.waitForFunction(() => window.dropslice.job().parts[0].place_x !== undefined);
  const after = await job(page);
  const p = after.parts[0];
  const inst = after.layout.instances.find((i) => i.part === 0);
  assert.ok(inst.placed, "placed");
  assert.deepEqual(inst.at, [p.place_x, p.place_y], "the layout puts it where the part says");
  const was = before.layout.instances.find((i) => i.part === 0).at;
  assert.ok(Math.hypot(inst.at[0] - was[0], inst.at[1] - was[1]) > 5, `moved from ${was} to ${inst.at}`);
  // the panel shows the place; Slice says the slice is out of date
  assert.equal(await page.inputValue("#part-place_x"), p.place_x.toFixed(2));
  assert.equal(await page.isChecked("#part-auto"), false);
  assert.match(await page.locator("#settings-status").innerText(), /The parts changed/);
  // Arrange clears it again
  await page.click("#btn-arrange");
  await page.waitForFunction(() => window.dropslice.job().parts[0].place_x === undefined);
  assert.deepEqual((await job(page)).layout.instances.find((i) => i.part === 0).at, was);
});

test("dragging the selected part in the layer view moves it by the mm dragged", async () => {
  const { page } = main;
  await page.click("#mode-layer");
  await page.click(".part-item:nth-child(1)");
  const before = (await job(page)).layout.instances.find((i) => i.part === 0);
  const { view } = await page.evaluate(() => window.dropslice.status());
  const box = await page.locator("#view").boundingBox();
  const toPx = (x, y) => [box.x + (x - view.cx) * view.scale + box.width / 2, box.y - (y - view.cy) * view.scale + box.height / 2];
  const [sx, sy] = toPx((before.min[0] + before.max[0]) / 2, (before.min[1] + before.max[1]) / 2);
  await page.mouse.move(sx, sy);
  await page.mouse.down();
  await page.mouse.move(sx + 40, sy - 20, { steps: 5 });
  await page.mouse.up();
  await page.waitForFunction(() => window.dropslice.job().parts[0].place_x !== undefined);
  const after = (await job(page)).layout.instances.find((i) => i.part === 0);
  assert.ok(Math.abs(after.at[0] - (before.at[0] + 40 / view.scale)) < 0.02, `x ${after.at[0]} vs ${before.at[0]} + ${40 / view.scale}`);
  assert.ok(Math.abs(after.at[1] - (before.at[1] + 20 / view.scale)) < 0.02, `y ${after.at[1]} vs ${before.at[1]} + ${20 / view.scale}`);
  const v = (await page.evaluate(() => window.dropslice.status())).view;
  assert.deepEqual(v, view, "the drag moved the part, not the view");
  await page.click("#btn-arrange");
  await page.waitForFunction(() => window.dropslice.job().parts[0].place_x === undefined);
  await open3d(page);
});

test("a job that does not fit says so and keeps the previous state", async () => {
  const { page } = main;
  await page.click(".part-item:nth-child(2)");
  const before = await job(page);
  await page.fill("#part-copies", "100");
  await page.press("#part-copies", "Enter");
  await page.waitForFunction(() => !document.getElementById("banner").hidden);
  const text = await page.locator("#banner").innerText();
  assert.match(text, /does not fit|do not fit|not every part fits/i);
  assert.match(text, /extruder_idler_quads/);
  const after = await job(page);
  assert.deepEqual(after.parts, before.parts, "the parts are as they were");
  assert.deepEqual(after.layout, before.layout);
  assert.equal(await page.inputValue("#part-copies"), "1", "the panel shows the part as it is");
  // a change that fits clears the message
  await page.fill("#part-copies", "2");
  await page.press("#part-copies", "Enter");
  await page.waitForFunction(() => window.dropslice.job().layout.instances.length === 3);
  assert.equal(await page.isVisible("#banner"), false);
  await page.fill("#part-copies", "1");
  await page.press("#part-copies", "Enter");
  await page.waitForFunction(() => window.dropslice.job().layout.instances.length === 2);
});

test("lay flat turns the part as the core says: a tilted slab ends up lying on its largest face", async () => {
  const { page } = main;
  // a 30 × 20 × 4 mm slab turned 30° about x: lying flat it is 4 mm tall
  const slab = boxStl(30, 20, 4, { deg: 30 });
  writeFileSync(join(tmp, "slab.stl"), slab);
  await page.setInputFiles("#add-input", join(tmp, "slab.stl"));
  await page.waitForFunction(() => window.dropslice.job().parts.length === 3);
  const inst = (j) => j.layout.instances.find((i) => i.part === 2);
  const tilted = inst(await job(page));
  assert.ok(tilted.max[2] - tilted.min[2] > 10, `tilted height ${tilted.max[2] - tilted.min[2]}`);
  await page.click("#part-lay-flat");
  await page.waitForFunction(() => window.dropslice.job().parts[2].rotate_x !== 0 || window.dropslice.job().parts[2].rotate_y !== 0);
  const j = await job(page);
  const flat = inst(j);
  assert.ok(Math.abs(flat.max[2] - flat.min[2] - 4) < 1e-3, `flat height ${flat.max[2] - flat.min[2]}`);
  assert.deepEqual(flat.rotate, [j.parts[2].rotate_x, j.parts[2].rotate_y, 0]);
  assert.equal(await page.inputValue("#part-rotate_x"), String(+j.parts[2].rotate_x.toFixed(4)));
  await page.click("#part-remove");
  await page.waitForFunction(() => window.dropslice.job().parts.length === 2);
});

test("save job → open job.json with its files in a fresh page: same layout, same G-code", async () => {
  const { page } = main;
  // slice the job as it is now (placed part, two copies) to compare with
  await page.click(".part-item:nth-child(2)");
  await page.fill("#part-copies", "2");
  await page.press("#part-copies", "Enter");
  await page.waitForFunction(() => window.dropslice.job().layout.instances.length === 3);
  await page.fill("#part-place_x", "40");
  await page.press("#part-place_x", "Enter");
  await page.waitForFunction(() => window.dropslice.job().parts[1].place_x === 40);
  await page.evaluate(() => (document.body.dataset.state = "picking"));
  await page.click("#btn-slice");
  await waitDone(page);
  const here = await job(page);
  const gcode = await downloadText(page);
  const [d] = await Promise.all([page.waitForEvent("download"), page.click("#btn-save-job")]);
  assert.equal(d.suggestedFilename(), "job.json");
  const jobFile = join(tmp, "job.json");
  await d.saveAs(jobFile);
  const saved = JSON.parse(readFileSync(jobFile, "utf8"));
  assert.deepEqual(saved.parts.map((p) => p.file), ["cube_20mm_ascii.stl", "extruder_idler_quads.obj"]);
  assert.equal(saved.parts[1].copies, 2);
  assert.equal(saved.parts[1].place_x, 40);
  // the settings that differ from the defaults only: none here (not `units`, nor units 2 and 3's)
  assert.deepEqual(saved.settings, {});

  // the job file first, its models later (asked for by name)
  const other = await openPage(env.browser, env.url);
  await waitDone(other.page, 60_000);
  await pick(other.page, jobFile);
  await other.page.waitForFunction(() => document.body.dataset.state === "idle");
  const banner = await other.page.locator("#banner").innerText();
  assert.match(banner, /Still missing: “cube_20mm_ascii\.stl”, “extruder_idler_quads\.obj”/);
  await pick(other.page, [idler, cube]);
  await waitDone(other.page);
  const there = await job(other.page);
  assert.deepEqual(there.layout.instances.map((i) => [i.part, i.copy, i.matrix]), here.layout.instances.map((i) => [i.part, i.copy, i.matrix]));
  assert.deepEqual(commands(await downloadText(other.page)), commands(gcode));
  await other.context.close();
});

test("a two-part preview link (models embedded) gives the same G-code in a fresh page", async () => {
  const { page } = main;
  const url = await shareLink(page);
  assert.match(url, /#p=.*&m=/, "models embedded");
  const other = await openPage(env.browser, url);
  await waitDone(other.page);
  assert.deepEqual((await job(other.page)).parts.map((p) => p.file), ["cube_20mm_ascii.stl", "extruder_idler_quads.obj"]);
  assert.deepEqual(commands(await downloadText(other.page)), commands(await downloadText(page)));
  await other.context.close();
  assert.ok(twoPartGcode.length > 0);
});

test("a job link too big to embed asks for its files, says which are missing, and takes them", async () => {
  const { page } = main;
  await pick(page, [benchy, cube]);
  const here = await waitDone(page);
  const url = await shareLink(page);
  const other = await openLinkAskingForFile(env.browser, url, /3DBenchy\.stl/);
  // one of the two: the other is named as missing
  await pick(other.page, cube);
  await other.page.waitForFunction(() => /Still missing: “3DBenchy\.stl”/.test(document.getElementById("banner").innerText));
  // a file that is not one of the link's is named
  await pick(other.page, idler);
  await other.page.waitForFunction(() => /extruder_idler_quads\.obj” is not one of them/.test(document.getElementById("banner").innerText));
  await pick(other.page, benchy);
  const there = await waitDone(other.page);
  assert.equal(there.droplets, here.droplets);
  assert.equal(there.layer, here.layer);
  await other.context.close();
});

test("a worker's refused import leaves none of the files asked for: the job queued behind it is refused, not prepared from the earlier file", async () => {
  // The page posts a worker's import and the job's opening together (client.ts syncThenOpen),
  // so the opening must not find an earlier file of the same name when the import failed.
  // (With the worker's clean-up after a refusal taken out, the job is prepared and this fails.)
  const { page } = main;
  const spec = { settings: {}, parts: [{ file: "cube_20mm_ascii.stl" }] };
  const r = await page.evaluate(
    async ({ spec, cubeText }) => {
      const w = new Worker(new URL("worker.js", location.href), { type: "module" });
      // the worker's first message is the module the page compiled (core/client.ts)
      w.postMessage({ kind: "module", module: await WebAssembly.compileStreaming(fetch("dropslice_bg.wasm")) });
      const pending = new Map();
      w.onmessage = (ev) => {
        const m = ev.data;
        if (m.kind === "result" || m.kind === "error") pending.get(m.id)?.(m);
      };
      let id = 0;
      const call = (kind, data) =>
        new Promise((resolve) => {
          pending.set(++id, resolve);
          w.postMessage({ id, kind, data });
        });
      const name = spec.parts[0].file;
      const good = new File([cubeText], name);
      // a binary STL header announcing 117 million facets in 300 bytes
      const bad = new File([new Uint8Array(300).fill(7)], "bad.stl");
      try {
        const added = await call("models_add", { files: [{ name, file: good }], hash: false });
        const opened = await call("open_job", { job: spec });
        // as syncThenOpen posts them: at once, the opening queued behind the import
        const [refused, reopened] = await Promise.all([
          call("models_add", { files: [{ name, file: good }, { name: "bad.stl", file: bad }], hash: false }),
          call("open_job", { job: spec }),
        ]);
        return { added: added.kind, opened: opened.kind, openedWhy: opened.data?.message, refused: refused.kind, refusal: refused.data?.message, reopened: reopened.kind, why: reopened.data?.message };
      } finally {
        w.terminate();
      }
    },
    { spec, cubeText: readFileSync(cube, "utf8") },
  );
  assert.equal(r.added, "result");
  assert.equal(r.opened, "result", `the job opens from the file while the worker holds it: ${r.openedWhy}`);
  assert.equal(r.refused, "error");
  assert.match(r.refusal, /not an STL file/);
  assert.equal(r.reopened, "error", "the job must not be prepared from the file held before the refused import");
  assert.match(r.why, new RegExp(spec.parts[0].file.replace(/[.]/g, "\\.")));
});

test("a part of 1,000,000 facets: the 3D view draws a decimated copy (at most 300,000 triangles)", async () => {
  const big = await openPage(env.browser, env.url);
  const { page, errors } = big;
  await waitDone(page, 60_000);
  await open3d(page);
  await pick(page, { name: "torus-1m.stl", mimeType: "model/stl", buffer: torusStl(1000, 500, 40, 12) });
  await page.waitForFunction(() => (window.dropslice.job()?.parts[0]?.mesh ?? 0) > 0 && window.dropslice.job().name === "torus-1m.stl", null, { timeout: 240_000 });
  const j = await job(page);
  assert.ok(j.parts[0].mesh <= 300_000 && j.parts[0].mesh > 10_000, `display triangles ${j.parts[0].mesh}`);
  // the slice uses the full mesh; the whole part is drawn at its top layer (the torus' slice:
  // until it has layers the status may still be the sample's)
  await page.waitForFunction(() => {
    const s = window.dropslice.status();
    return s.name === "torus-1m.stl" && s.layers > 0;
  }, null, { timeout: 240_000 });
  await page.evaluate(() => window.dropslice.show(window.dropslice.status().layers - 1));
  const px = await pixels3d(page);
  assert.ok(px.part.n > 5000, `part pixels ${px.part.n}`);
  const facets = await page.locator("#stat-facets").innerText();
  assert.equal(facets, "1,000,000");
  // a slice still running is cancelled; checked and clicked in one step in the page (the
  // slice may end between a check here and a click)
  await page.evaluate(() => {
    const b = document.getElementById("btn-cancel");
    if (b && b.checkVisibility()) b.click();
  });
  assert.deepEqual(errors, []);
  await big.context.close();
});

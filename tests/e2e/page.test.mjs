// End-to-end tests of the page in headless Chromium (playwright-core + Debian's chromium).
// Needs dist/ (scripts/build.sh) and, for the G-code comparison, target/release/dropslice.
import { after, before, test } from "node:test";
import assert from "node:assert/strict";
import { execFileSync } from "node:child_process";
import { existsSync, mkdtempSync, readFileSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { benchy, canvasPixels, inkPixels, openLinkAskingForFile, openPage, parseGcode, pick, repo, shareLink, startWithPage, status, stop, torusStl, waitDone, waitSettled } from "./helpers.mjs";

let env;
let main; // the page most tests share
const tmp = mkdtempSync(join(tmpdir(), "dropslice-e2e-"));
const cli = join(repo, "target/release/dropslice");

before(async () => ({ env, main } = await startWithPage()));

after(() => stop(env, tmp));

test("the sample part is sliced and drawn on first visit", async () => {
  const { page, errors } = main;
  const s = await waitDone(page, 60_000);
  assert.equal(s.name, "sample-block-with-boss.stl");
  assert.ok(s.layers > 50, `layers ${s.layers}`);
  assert.ok(s.counts.outer > 0 && s.counts.inner > 0 && s.counts.fill > 0, JSON.stringify(s.counts));
  await page.waitForTimeout(100);
  assert.ok((await inkPixels(page)) > 10_000, "droplets are drawn");
  assert.match(await page.locator("#stat-droplets").innerText(), /^[\d,]+$/);
  assert.deepEqual(errors, []);
});

test("invalid settings are flagged before slicing", async () => {
  const { page } = main;
  await page.fill("#set-layer_height", "-1");
  assert.equal(await page.getAttribute("#set-layer_height", "aria-invalid"), "true");
  assert.match(await page.locator(".field.invalid .message").first().innerText(), /at least 0.0001/);
  assert.equal(await page.isDisabled("#btn-slice"), true);
  await page.fill("#set-layer_height", "abc");
  assert.match(await page.locator(".field.invalid .message").first().innerText(), /not a number/);
  await page.fill("#set-layer_height", "0.2");
  assert.equal(await page.isDisabled("#btn-slice"), false);
  assert.equal(await page.locator(".field.invalid").count(), 0);
});

test("3DBenchy: progress reaches 100 %, the slider changes the canvas", async () => {
  const { page } = main;
  await page.evaluate(() => {
    window.__pct = [];
    const p = document.getElementById("progress");
    new MutationObserver(() => window.__pct.push(Number(p.dataset.percent))).observe(p, { attributes: true, attributeFilter: ["data-percent"] });
  });
  const t0 = Date.now();
  await pick(page, benchy);
  await page.waitForFunction(() => document.body.dataset.state === "slicing");
  // the progress box (with Cancel) lies clear of the view tools above the canvas
  const boxes = await page.evaluate(() => [document.getElementById("progress"), document.querySelector(".view-tools")].map((e) => {
    const r = e.getBoundingClientRect();
    return { left: r.left, right: r.right, top: r.top, bottom: r.bottom, shown: !e.hidden && r.width > 0 };
  }));
  const [bar, tools] = boxes;
  assert.ok(bar.shown && tools.shown, `both shown: ${JSON.stringify(boxes)}`);
  const overlap = bar.left < tools.right && tools.left < bar.right && bar.top < tools.bottom && tools.top < bar.bottom;
  assert.ok(!overlap, `the progress box clear of the view tools: ${JSON.stringify(boxes)}`);
  const s = await waitDone(page, 240_000);
  console.log(`# 3DBenchy sliced in the page in ${s.seconds.toFixed(2)} s (file chosen -> G-code ready; ${((Date.now() - t0) / 1000).toFixed(1)} s as the test saw it) with ${s.workers} worker(s)`);
  assert.ok(s.seconds > 0, "the page timed its slice");
  const pct = await page.evaluate(() => window.__pct);
  assert.ok(pct.length > 3, `progress updates: ${pct}`);
  assert.equal(Math.max(...pct), 100);
  assert.equal(s.layers, 240);
  assert.equal(s.done, 240);
  assert.match(await page.locator("#stat-layers").innerText(), /^240$/);

  await page.waitForTimeout(100);
  const before = await canvasPixels(page);
  await page.locator("#layer").fill("200");
  await page.waitForTimeout(150);
  assert.equal((await status(page)).layer, 200);
  const after200 = await canvasPixels(page);
  assert.notEqual(after200, before, "moving the slider redraws");
  // arrow keys move one layer
  await page.locator("#view").focus();
  await page.keyboard.press("ArrowDown");
  assert.equal((await status(page)).layer, 199);
  await page.keyboard.press("ArrowUp");
  assert.equal((await status(page)).layer, 200);
  await page.waitForTimeout(100);
  assert.ok((await inkPixels(page)) > 1000);
});

test("the downloaded .gco has the CLI's commands", async (t) => {
  if (!existsSync(cli)) return t.skip("target/release/dropslice not built");
  const { page } = main;
  const [download] = await Promise.all([page.waitForEvent("download"), page.click("#btn-download")]);
  assert.equal(download.suggestedFilename(), "3DBenchy.gco");
  const mine = join(tmp, "page.gco");
  await download.saveAs(mine);
  const theirs = join(tmp, "cli.gco");
  execFileSync(cli, [benchy, "-o", theirs, "-q"], { stdio: "inherit" });
  const a = parseGcode(readFileSync(mine, "utf8"));
  const b = parseGcode(readFileSync(theirs, "utf8"));
  assert.equal(a.length, b.length, "same number of commands");
  for (let i = 0; i < a.length; i++) {
    const p = a[i];
    const q = b[i];
    if (p.code !== q.code || Math.abs(p.x - q.x) > 1e-4 || Math.abs(p.y - q.y) > 1e-4 || Math.abs(p.z - q.z) > 1e-4) {
      assert.fail(`command ${i}: page ${JSON.stringify(p)} vs CLI ${JSON.stringify(q)}`);
    }
  }
  const text = readFileSync(mine, "utf8");
  assert.match(text, /^; dropslice /);
  assert.match(text, /; layer_height = 0\.2/);
  assert.match(text, /; end of code: 240 layers/);
  // the totals in the page's header equal the CLI's
  const totals = (s) => s.split("\n").filter((l) => l.startsWith("; droplets ")).join("\n");
  assert.equal(totals(text), totals(readFileSync(theirs, "utf8")));

  // the page opens its own .gco back: same layers and droplets
  const sliced = await status(page);
  await pick(page, mine);
  const viewed = await waitDone(page, 120_000);
  assert.equal(viewed.layers, sliced.layers);
  // G25 lines re-expanded from their written coordinates give the core's counts exactly
  assert.equal(viewed.droplets, sliced.droplets);
  // the header's droplets by role: the slice's (the commands alone do not tell outer from inner)
  assert.deepEqual(viewed.counts, sliced.counts);
  assert.ok((await inkPixels(page)) > 1000);
});

test("a preview link with the embedded model reproduces the slice", async () => {
  const { page } = main;
  await page.evaluate(() => (document.body.dataset.state = "picking"));
  await page.click("#btn-sample");
  await waitDone(page, 60_000);
  await page.fill("#set-contours", "3");
  await page.evaluate(() => (document.body.dataset.state = "picking"));
  await page.click("#btn-slice");
  await waitDone(page, 60_000);
  await page.locator("#layer").fill("70");
  await page.waitForTimeout(100);
  const here = await status(page);
  const url = await shareLink(page);
  assert.match(url, /#p=.*&m=/, "model embedded");

  const other = await openPage(env.browser, url);
  const there = await waitDone(other.page, 60_000);
  assert.equal(there.layer, 70);
  assert.equal(there.droplets, here.droplets);
  assert.deepEqual(there.layerDroplets, here.layerDroplets);
  assert.equal(await other.page.inputValue("#set-contours"), "3");
  assert.ok(Math.abs(there.view.scale - here.view.scale) < 1e-9);
  await other.context.close();
  await page.fill("#set-contours", "2");
});

test("a preview link of a big model asks for the file and checks it", async () => {
  const { page } = main;
  await pick(page, benchy);
  await waitDone(page, 240_000);
  await page.locator("#layer").fill("120");
  const here = await status(page);
  const url = await shareLink(page);

  const other = await openLinkAskingForFile(env.browser, url, /3DBenchy\.stl/);
  // a different file is recognised as different
  await pick(other.page, join(benchy, "../cube_20mm_ascii.stl"));
  await waitDone(other.page, 60_000);
  assert.match(await other.page.locator("#link-note").innerText(), /does not match/);
  await other.context.close();

  const third = await openPage(env.browser, url);
  await third.page.waitForFunction(() => !document.getElementById("link-note").hidden);
  await pick(third.page, benchy);
  const there = await waitDone(third.page, 240_000);
  assert.match(await third.page.locator("#link-note").innerText(), /matches/);
  assert.equal(there.layer, 120);
  assert.equal(there.droplets, here.droplets);
  await third.context.close();
});

test("a garbage file shows an error and the next slice works", async () => {
  const { page } = main;
  const junk = Buffer.alloc(5000);
  for (let i = 0; i < junk.length; i++) junk[i] = (i * 7919 + 13) % 251;
  await pick(page, { name: "garbage.stl", mimeType: "model/stl", buffer: junk });
  const s = await waitSettled(page, 30_000);
  assert.equal(s.state, "error");
  assert.equal(await page.isVisible("#banner"), true);
  assert.match(await page.locator("#banner").innerText(), /Cannot read the model file/i);
  await page.evaluate(() => (document.body.dataset.state = "picking"));
  await page.click("#btn-sample");
  const ok = await waitDone(page, 60_000);
  assert.equal(ok.name, "sample-block-with-boss.stl");
  assert.equal(await page.isVisible("#banner"), false);
});

test("a crash in the wasm becomes a message and the page recovers", async () => {
  const { page } = main;
  await page.evaluate(() => window.dropslice.crash().catch(() => {}));
  await page.waitForFunction(() => !document.getElementById("banner").hidden);
  const text = await page.locator("#banner").innerText();
  assert.match(text, /crashed/);
  assert.match(text, /crash_for_test/);
  // the fresh workers got the finished slice's model back: its download still works
  const [download] = await Promise.all([page.waitForEvent("download"), page.click("#btn-download")]);
  assert.equal(download.suggestedFilename(), "sample-block-with-boss.gco");
  await page.evaluate(() => (document.body.dataset.state = "picking"));
  await page.click("#btn-sample");
  await waitDone(page, 60_000);
});

test("Cancel stops a large slice at once and a new slice works", async () => {
  const { page } = main;
  const torus = torusStl(600, 250, 40, 12); // 300,000 facets, 24 mm tall
  await page.fill("#set-layer_height", "0.05");
  await pick(page, { name: "torus.stl", mimeType: "model/stl", buffer: torus });
  await page.waitForFunction(() => window.dropslice.status().done >= 2, null, { timeout: 120_000, polling: 50 });
  const t0 = Date.now();
  try {
    await page.click("#btn-cancel");
    const s = await waitSettled(page, 15_000);
    assert.equal(s.state, "cancelled");
    // at once: the workers are terminated, not waited for (the whole slice takes minutes);
    // the bound leaves room for a busy machine
    assert.ok(Date.now() - t0 < 10_000, "cancel is immediate");
    assert.equal(await page.isVisible("#progress"), false);
  } finally {
    await page.fill("#set-layer_height", "0.2");
  }
  await page.evaluate(() => (document.body.dataset.state = "picking"));
  await page.click("#btn-sample");
  const ok = await waitDone(page, 60_000);
  assert.equal(ok.name, "sample-block-with-boss.stl");
  assert.ok(ok.droplets > 0);
});

test("on a high-DPI screen the canvas has one pixel per device pixel", async () => {
  const hi = await openPage(env.browser, env.url, { width: 1200, height: 800, scale: 2 });
  await waitDone(hi.page, 60_000);
  const dims = await hi.page.evaluate(() => {
    const c = document.getElementById("view");
    const r = c.getBoundingClientRect();
    return { w: c.width, h: c.height, cw: r.width, ch: r.height };
  });
  assert.equal(dims.w, Math.round(dims.cw * 2));
  assert.equal(dims.h, Math.round(dims.ch * 2));
  await hi.context.close();
});

test("three workers give the same slice as one; evicted layers are re-planned on demand", async () => {
  const multi = await openPage(env.browser, `${env.url}?workers=3&cache=2`);
  const { page } = multi;
  await waitDone(page, 60_000);
  await pick(page, benchy);
  const s = await waitDone(page, 240_000);
  assert.equal(s.workers, 3);
  assert.equal(s.layers, 240);
  assert.ok(s.cached < 240, `only part of the layers stay cached (${s.cached})`);
  const single = await openPage(env.browser, env.url);
  await waitDone(single.page, 60_000);
  await pick(single.page, benchy);
  const ref = await waitDone(single.page, 240_000);
  assert.equal(s.droplets, ref.droplets);
  assert.deepEqual(s.counts, ref.counts);
  await single.context.close();
  // a layer far from the last one shown was evicted and comes back from a worker
  for (const layer of [3, 230, 5]) {
    await page.locator("#layer").fill(String(layer));
    await page.waitForFunction((l) => window.dropslice.status().shown === l, layer, { timeout: 20_000 });
  }
  assert.equal(await page.isVisible("#banner"), false);
  await page.waitForTimeout(100);
  assert.ok((await inkPixels(page)) > 500);
  // the download still has every layer
  const [download] = await Promise.all([page.waitForEvent("download"), page.click("#btn-download")]);
  const file = join(tmp, "multi.gco");
  await download.saveAs(file);
  const text = readFileSync(file, "utf8");
  assert.match(text, /; end of code: 240 layers/);
  assert.equal(parseGcode(text).filter((c) => c.code === "G26").length, ref.counts.outer + ref.counts.inner);
  await multi.context.close();
});

test("drag and drop opens a file; wheel zooms, dragging pans, Fit restores", async () => {
  const { page } = main;
  const cube = readFileSync(join(benchy, "../cube_20mm_ascii.stl"), "utf8");
  await page.evaluate(() => (document.body.dataset.state = "picking"));
  await page.evaluate((text) => {
    const dt = new DataTransfer();
    dt.items.add(new File([text], "dropped-cube.stl", { type: "model/stl" }));
    const target = document.getElementById("view");
    for (const type of ["dragenter", "dragover", "drop"]) {
      target.dispatchEvent(new DragEvent(type, { dataTransfer: dt, bubbles: true, cancelable: true }));
    }
  }, cube);
  const s = await waitDone(page, 60_000);
  assert.equal(s.name, "dropped-cube.stl");
  assert.equal(s.layers, 100);
  assert.equal(await page.isVisible("#drop-overlay"), false);
  // the notice that the job was replaced sits above the stage (the canvas is shorter while it
  // shows, and it goes by itself): closed, so that the canvas keeps its size from here on, and
  // the part fitted to that size
  if (await page.isVisible("#undo-note")) await page.click("#undo-close");
  await page.click("#btn-fit");

  const box = await page.locator("#view").boundingBox();
  await page.mouse.move(box.x + box.width / 2, box.y + box.height / 2);
  const v0 = (await status(page)).view;
  await page.mouse.wheel(0, -300);
  await page.waitForFunction((s0) => window.dropslice.status().view.scale > s0 * 1.5, v0.scale);
  await page.mouse.down();
  await page.mouse.move(box.x + box.width / 2 + 100, box.y + box.height / 2 + 40, { steps: 4 });
  await page.mouse.up();
  const v1 = (await status(page)).view;
  assert.ok(v1.cx < v0.cx, "dragging right moves the view left");
  assert.ok(v1.cy > v0.cy, "dragging down moves the view up");
  await page.click("#btn-fit");
  const v2 = (await status(page)).view;
  assert.ok(Math.abs(v2.scale - v0.scale) < 1e-9 && Math.abs(v2.cx - v0.cx) < 1e-9);
});

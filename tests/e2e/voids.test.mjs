// The void overlay in the page: the analysis figures in the statistics, the overlay on the
// canvas, "Go to worst layer". Needs dist/ (scripts/build.sh).
import { after, before, test } from "node:test";
import assert from "node:assert/strict";
import { boxStl, canvasPixels, pick, startWithPage, status, stop, voidPixels, waitSettled } from "./helpers.mjs";

let env;
let main;

before(async () => ({ env, main } = await startWithPage()));

after(() => stop(env));

test("the voids overlay: figures, canvas, worst layer", async () => {
  const { page, errors } = main;
  let s = await waitSettled(page, 60_000);
  assert.equal(s.state, "done");
  assert.equal(s.analysed, 0, "plain slicing does not analyse");
  assert.equal(await page.locator("#stat-coverage").innerText(), "–");
  assert.equal(await page.isDisabled("#btn-worst"), true);
  await page.waitForTimeout(150);
  const plain = await canvasPixels(page);
  const plainMagenta = await voidPixels(page);

  // turning the overlay on analyses every layer of the finished slice
  const t0 = Date.now();
  await page.check("#opt-voids");
  await page.waitForFunction(() => {
    const st = window.dropslice.status();
    return st.state === "done" && st.analysed === st.layers && st.masked;
  }, null, { timeout: 120_000, polling: 100 });
  s = await status(page);
  console.log(`# sample part: ${s.layers} layers analysed in the page in ${((Date.now() - t0) / 1000).toFixed(1)} s`);
  await page.waitForTimeout(150);
  const overlay = await canvasPixels(page);
  assert.notEqual(overlay, plain, "the overlay changes the canvas");
  const magenta = await voidPixels(page);
  assert.ok(magenta > plainMagenta + 500, `void pixels ${plainMagenta} -> ${magenta}`);
  assert.equal(await page.isVisible("#legend-voids"), true);

  // figures: this layer, the part, the worst layer
  const coverage = await page.locator("#stat-coverage").innerText();
  const m = /^(\d+\.\d) %$/.exec(coverage);
  assert.ok(m, `coverage "${coverage}"`);
  assert.ok(Number(m[1]) > 60 && Number(m[1]) < 95, coverage);
  assert.match(await page.locator("#stat-void").innerText(), /^\d+\.\d+ mm²$/);
  assert.match(await page.locator("#stat-largest").innerText(), /^\d+\.\d+ mm²/);
  assert.match(await page.locator("#stat-part-coverage").innerText(), /^\d+\.\d %$/);
  assert.match(await page.locator("#stat-worst").innerText(), /^[\d,]+ · \d+\.\d+ mm²$/);

  // "Go to worst layer" moves the slider there
  assert.notEqual(s.worst, null);
  if (s.worst === s.layer) await page.evaluate(() => window.dropslice.show(0));
  await page.click("#btn-worst");
  s = await status(page);
  assert.equal(s.layer, s.worst);
  assert.equal(Number(await page.inputValue("#layer")), s.worst);
  assert.match(await page.locator("#layer-label").innerText(), new RegExp(`^Layer ${s.worst + 1} /`));
  assert.match(await page.locator("#stat-worst").innerText(), new RegExp(`^${s.worst + 1} · `));

  // off and on again at the same layer: the overlay comes and goes without a new analysis
  await page.waitForFunction(() => window.dropslice.status().masked, null, { timeout: 30_000 });
  await page.waitForTimeout(150);
  const on = await canvasPixels(page);
  await page.uncheck("#opt-voids");
  await page.waitForTimeout(150);
  const off = await canvasPixels(page);
  assert.notEqual(off, on, "turning the overlay off redraws without it");
  assert.equal(await page.isVisible("#legend-voids"), false);
  await page.check("#opt-voids");
  await page.waitForTimeout(150);
  assert.equal(await canvasPixels(page), on);
  assert.equal((await status(page)).state, "done");

  // slicing again with the overlay on analyses during the slice
  await page.click("#btn-slice");
  s = await waitSettled(page, 60_000);
  assert.equal(s.state, "done");
  assert.equal(s.analysed, s.layers);
  await page.uncheck("#opt-voids");
  assert.deepEqual(errors, []);
});

test("a sheet too large to analyse: sliced, and the page says why the voids are not analysed", async () => {
  // 600 × 600 mm, one layer of about 8 million droplets: its analysis would take several GB
  // (the core's bound is 1 GB a layer); a 700 mm sheet once panicked the worker
  const { page, errors } = main;
  await waitSettled(page, 60_000);
  for (const name of ["plate_x", "plate_y"]) {
    await page.$eval(`#settings [name="${name}"]`, (el) => {
      for (let d = el.closest("details"); d; d = d.parentElement?.closest("details")) d.open = true;
    });
    await page.fill(`#settings [name="${name}"]`, "1000");
    await page.press(`#settings [name="${name}"]`, "Tab");
  }
  await page.check("#opt-voids");
  await waitSettled(page, 60_000);
  await pick(page, [{ name: "sheet.stl", mimeType: "model/stl", buffer: boxStl(600, 600, 0.2) }]);
  // the slice completes without the analysis, then the analysis pass says why
  await page.waitForFunction(() => {
    const b = document.getElementById("banner");
    return !b.hidden && /cannot be analysed/i.test(b.innerText);
  }, null, { timeout: 240_000, polling: 200 });
  const s = await waitSettled(page, 60_000);
  assert.equal(s.layers, 1);
  assert.equal(s.analysed, 0);
  const banner = await page.locator("#banner").innerText();
  assert.match(banner, /would take about [\d.]+ GB to analyse, more than the 1 GB allowed/);
  assert.match(banner, /droplet_aspect/);
  assert.equal(await page.isDisabled("#btn-download"), false, "the slice can be downloaded");
  await page.uncheck("#opt-voids");
  assert.deepEqual(errors, []);
});

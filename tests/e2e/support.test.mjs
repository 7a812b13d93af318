// Overhangs, support and the second discharge unit in the page (issue 13): the overhang overlay
// on 3DBenchy's cabin roof checked against this file's own reading of the downloaded G-code, the
// support switch (support droplets on the canvas and in the statistics, T lines in the
// download), the 3D view's overhang tint, and a two-material job. Needs dist/ (scripts/build.sh).
import { after, before, test } from "node:test";
import assert from "node:assert/strict";
import { mkdtempSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { benchy, countPixels, downloadText, open3d, pick, pixels3d, startWithPage, status, stop, twoCubesSecondOnUnit, waitDone, waitSettled } from "./helpers.mjs";

let env;
let main;
const tmp = mkdtempSync(join(tmpdir(), "dropslice-support-"));

before(async () => ({ env, main } = await startWithPage()));

after(() => stop(env, tmp));

/** The colours of render.ts (SUPPORT_COLOR, UNIT1_COLOR, OVERHANG_COLOR) as pixel tests. */
const SUPPORT = "r === 0x10 && g === 0x98 && b === 0xad";
/** The unit-1 colour within a few levels: the selected part (here the unit-1 one) is tinted
 *  lightly in the layer view. */
const UNIT1 = "Math.abs(r - 0x70) < 12 && Math.abs(g - 0x48) < 12 && Math.abs(b - 0xe8) < 12";
const OVERHANG = "r === 0xe8 && g === 0x10 && b === 0x7a";
const ROLE0 = "r === 0xd9 && g === 0x48 && b === 0x0f";

/**
 * This test's own reading of a .gco: per layer (a Z change) the droplet centres with their unit
 * (T0/T1; G26 one droplet, G25 one every B of its unit from the current position, B and B₁
 * from the header), and the droplets of each layer above the first with no droplet of the
 * layer below within B_below/2 + overhang_limit·B (docs/support.md, "The rule").
 */
function readBack(text) {
  const header = {};
  for (const m of text.matchAll(/^; ([a-z0-9_]+) = (\S+)/gm)) header[m[1]] ??= m[2];
  const h = Number(header.layer_height);
  const b = [h * Number(header.droplet_aspect), h * Number(header.unit1_droplet_aspect ?? 1.04)];
  const limit = Number(header.overhang_limit ?? 0.5) * b[0];
  const layers = [];
  let unit = 0;
  let at = [0, 0];
  let z = NaN;
  let tLines = 0;
  for (const raw of text.split("\n")) {
    const line = raw.trim();
    if (!line || line.startsWith(";")) continue;
    const [code, ...words] = line.split(/\s+/);
    if (code === "T0" || code === "T1") {
      unit = Number(code[1]);
      tLines++;
      continue;
    }
    const w = {};
    for (const x of words) w[x[0]] = Number(x.slice(1));
    if (w.Z !== undefined && w.Z !== z) {
      z = w.Z;
      layers.push([]);
    }
    const to = [w.X ?? at[0], w.Y ?? at[1]];
    if (code === "G26") layers.at(-1).push([to[0], to[1], unit]);
    else if (code === "G25") {
      const l = Math.hypot(to[0] - at[0], to[1] - at[1]);
      const n = Math.floor(l / b[unit] + 1e-9) + 1;
      for (let j = 0; j < n; j++) {
        const t = l > 0 ? (j * b[unit]) / l : 0;
        layers.at(-1).push([at[0] + t * (to[0] - at[0]), at[1] + t * (to[1] - at[1]), unit]);
      }
    }
    at = to;
  }
  /** Layer n's droplets without support (a grid of the layer below, cells of the largest reach). */
  const unsupported = (n) => {
    if (n === 0) return 0;
    const reach = Math.max(b[0], b[1]) / 2 + limit;
    const key = (x, y) => `${Math.floor(x / reach)},${Math.floor(y / reach)}`;
    const grid = new Map();
    for (const d of layers[n - 1]) {
      const k = key(d[0], d[1]);
      if (!grid.has(k)) grid.set(k, []);
      grid.get(k).push(d);
    }
    let count = 0;
    for (const [x, y] of layers[n]) {
      const cx = Math.floor(x / reach);
      const cy = Math.floor(y / reach);
      let ok = false;
      for (let i = -1; i <= 1 && !ok; i++) {
        for (let j = -1; j <= 1 && !ok; j++) {
          ok = (grid.get(`${cx + i},${cy + j}`) ?? []).some(([u, v, k]) => (x - u) ** 2 + (y - v) ** 2 <= (b[k] / 2 + limit + 1e-6) ** 2);
        }
      }
      if (!ok) count++;
    }
    return count;
  };
  const unit1 = layers.reduce((a, l) => a + l.filter((d) => d[2] === 1).length, 0);
  return { layers, unsupported, unit1, tLines };
}

/** Turns the overhang overlay on (if it is not) and waits for the current layer's marks. */
async function overlayMarks(page) {
  if (!(await page.isChecked("#opt-overhangs"))) await page.check("#opt-overhangs");
  await page.waitForFunction(() => window.dropslice.status().overhangsMarked !== null, null, { timeout: 60_000 });
  await page.waitForTimeout(150);
  return (await status(page)).overhangsMarked;
}

test("3DBenchy: the overhang overlay on the cabin roof, then the support switch", async () => {
  const { page, errors } = main;
  await waitSettled(page, 60_000);
  await pick(page, benchy);
  let s = await waitDone(page);
  assert.equal(s.counts.support ?? 0, 0, "no support without the switch");
  assert.equal(await page.isChecked("#opt-support"), false);
  assert.equal(await page.isVisible("#unit-stats"), false);

  // the worst overhang (the core's figure): its button goes there
  assert.notEqual(s.worstOverhang, null);
  await page.evaluate(() => window.dropslice.show(0));
  await page.click("#btn-worst-overhang");
  s = await status(page);
  assert.equal(s.layer, s.worstOverhang);
  assert.match(await page.locator("#stat-overhang-worst").innerText(), new RegExp(`^${s.layer + 1} · [\\d.]+ mm²$`));
  assert.match(await page.locator("#stat-overhang-layer").innerText(), /^[\d.]+ mm²$/);
  assert.match(await page.locator("#stat-overhang-part").innerText(), /^[\d.]+ mm²$/);

  // the overlay marks exactly the droplets this test's reading of the download finds unsupported
  const off = readBack(await downloadText(page));
  assert.equal(off.tLines, 0, "no T lines without support");
  assert.equal(off.layers.length, s.layers);
  const roof = s.layer;
  const marked = await overlayMarks(page);
  console.log(`# 3DBenchy layer ${roof + 1} (worst overhang): ${marked} droplets marked, ${off.unsupported(roof)} by the G-code's reading`);
  assert.equal(marked, off.unsupported(roof));
  assert.ok(marked > 1000, `the cabin roof overhangs: ${marked}`);
  await page.click("#btn-fit");
  await page.waitForTimeout(200);
  const overlayPixels = await countPixels(page, OVERHANG);
  assert.ok(overlayPixels > 500, `overlay pixels ${overlayPixels}`);
  assert.equal(await page.isVisible("#legend-overhangs"), true);
  // the first layer rests on the plate
  await page.evaluate(() => window.dropslice.show(0));
  assert.equal(await overlayMarks(page), 0);

  // the support switch sets the setting and slices with support
  await page.check("#opt-support");
  assert.equal(await page.inputValue("#set-support"), "unit1");
  await page.click("#btn-slice");
  s = await waitDone(page);
  assert.ok(s.counts.support > 0, `support droplets ${s.counts.support}`);
  assert.equal(s.unitDroplets[1], s.counts.support, "all unit-1 droplets are support");
  const shown = Number((await page.locator("#stat-support").innerText()).replace(/[^\d]/g, ""));
  assert.equal(shown, s.counts.support);
  assert.equal(await page.isVisible("#unit-stats"), true);
  assert.match(await page.locator("#stat-mass1").innerText(), /^\d+\.\d\d g$/);
  assert.equal(await page.isVisible("#legend-support"), true);

  // a hull layer with the most support: its droplets in the support colour
  const per = await page.evaluate(() => window.dropslice.layerUnits());
  let hull = 1;
  for (let i = 1; i < Math.min(per.length, 100); i++) if (per[i][0] > per[hull][0]) hull = i;
  assert.ok(per[hull][0] > 0, "support under the hull");
  await page.uncheck("#opt-overhangs");
  await page.evaluate((i) => window.dropslice.show(i), hull);
  await page.click("#btn-fit");
  await page.waitForTimeout(200);
  const supportPixels = await countPixels(page, SUPPORT);
  console.log(`# 3DBenchy with support: ${s.counts.support} support droplets; layer ${hull + 1}: ${per[hull][0]} (${supportPixels} px)`);
  assert.ok(supportPixels > 300, `support pixels ${supportPixels}`);

  // the download: T lines, as many unit-1 droplets as the statistics, and the roof carried
  const on = readBack(await downloadText(page));
  assert.ok(on.tLines > 0, "T lines");
  assert.equal(on.unit1, s.counts.support);
  await page.evaluate((i) => window.dropslice.show(i), roof);
  const after = await overlayMarks(page);
  assert.equal(after, on.unsupported(roof));
  assert.ok(after * 50 < marked, `with support the roof layer has ${after} unsupported droplets (without: ${marked})`);

  // the 3D view tints the overhanging faces with the core's threshold for the settings
  await open3d(page);
  await page.waitForFunction(() => window.dropslice.view3d()?.overhang != null, null, { timeout: 30_000 });
  // the whole part (the hull's flared underside faces down beyond the rule), framed
  await page.evaluate(() => window.dropslice.show(window.dropslice.status().layers - 1));
  await page.waitForTimeout(500);
  const state = await page.evaluate(() => window.dropslice.view3d());
  const t = 0.5 * 1.04; // overhang_limit · B / H with the defaults
  assert.ok(Math.abs(state.overhang - t / Math.hypot(1, t)) < 1e-9, `threshold ${state.overhang}`);
  const tinted = (await pixels3d(page)).tint; // magenta-red, dim (faces down)
  console.log(`# 3D view: ${tinted} pixels of overhanging faces`);
  assert.ok(tinted > 100, `tinted pixels ${tinted}`);
  await page.click("#mode-layer");
  await page.uncheck("#opt-overhangs");
  await page.uncheck("#opt-support");
  assert.deepEqual(errors, []);
});

test("a two-material job: two colours on the canvas, T lines in the download", async () => {
  const { page, errors } = main;
  await twoCubesSecondOnUnit(page, tmp, 1);
  await page.click("#btn-slice");
  const s = await waitDone(page);
  assert.ok(s.unitDroplets[1] > 0, "unit-1 droplets");
  assert.equal(s.counts.support ?? 0, 0);
  await page.evaluate((i) => window.dropslice.show(i), Math.floor(s.layers / 2));
  await page.click("#mode-layer");
  await page.click("#btn-fit");
  await page.waitForTimeout(200);
  assert.ok((await countPixels(page, UNIT1)) > 300, "the unit-1 part in its colour");
  assert.ok((await countPixels(page, ROLE0)) > 300, "the unit-0 part in the role colours");
  assert.equal(await page.isVisible("#legend-unit1"), true);
  const g = readBack(await downloadText(page));
  assert.ok(g.tLines > 0, "T lines");
  assert.equal(g.unit1, s.unitDroplets[1]);
  // each unit's droplets lie in its part's box on the plate (the core's layout)
  const { layout } = await page.evaluate(() => window.dropslice.job());
  const box = (unit) => layout.instances.find((x) => x.unit === unit);
  for (const unit of [0, 1]) {
    const { min, max } = box(unit);
    const mine = g.layers.flat().filter((d) => d[2] === unit);
    assert.ok(mine.length > 0, `unit ${unit} has droplets`);
    const outside = mine.filter(([x, y]) => x < min[0] || x > max[0] || y < min[1] || y > max[1]);
    assert.equal(outside.length, 0, `unit ${unit}: ${outside.length} droplets outside its part`);
  }
  assert.deepEqual(errors, []);
});

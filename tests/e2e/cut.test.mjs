// The vertical cut: a line on the layer view, the section through the layers below it, the
// 3D estimate's voids from the core. Needs dist/ (scripts/build.sh).
import { after, before, test } from "node:test";
import assert from "node:assert/strict";
import { openPage, startWithPage, status, stop, waitSettled } from "./helpers.mjs";

let env;
let main;

before(async () => ({ env, main } = await startWithPage()));

after(() => stop(env));

const cutStatus = (page) => page.evaluate(() => window.dropslice.cut().status());

/** Waits until the core answered for every layer of the current line. */
async function waitCut(page, layers) {
  await page.waitForFunction((n) => {
    const c = window.dropslice.cut().status();
    return c.resolved === n && c.pending === 0;
  }, layers, { timeout: 120_000, polling: 100 });
  await page.evaluate(() => window.dropslice.cut().redraw());
  return cutStatus(page);
}

/** Rows (device px) of the cut canvas holding pixels of each role's colour, the void colour,
 *  and the canvas as a string to compare. */
function cutPixels(page) {
  return page.evaluate(() => {
    const c = document.getElementById("cut-view");
    const d = c.getContext("2d").getImageData(0, 0, c.width, c.height).data;
    const near = (i, rgb) => Math.abs(d[i] - rgb[0]) < 12 && Math.abs(d[i + 1] - rgb[1]) < 12 && Math.abs(d[i + 2] - rgb[2]) < 12;
    // render.ts ROLE_COLORS, and the void colour (214, 51, 132) at 0.9 over anything
    const roles = [[0xd9, 0x48, 0x0f], [0xf5, 0x9f, 0x00], [0x3b, 0x8f, 0xdd]];
    const rows = new Set();
    let voids = 0;
    let coloured = 0;
    for (let y = 0; y < c.height; y++) {
      for (let x = 0; x < c.width; x++) {
        const i = 4 * (y * c.width + x);
        if (roles.some((r) => near(i, r))) {
          rows.add(y);
          coloured++;
        }
        if (d[i] > 180 && d[i + 1] < 90 && d[i + 2] > 100 && d[i + 2] < 160) voids++;
      }
    }
    return { rows: rows.size, coloured, voids, image: c.toDataURL() };
  });
}

test("the cut draws the droplets of many layers, moves with its line and shows the core's voids", async () => {
  const { page, errors } = main;
  const s = await waitSettled(page, 60_000);
  assert.equal(s.state, "done");
  assert.ok(s.layers > 20);
  // the tool puts a line through the part's middle and opens the cut
  await page.click("#btn-cut");
  assert.equal(await page.isVisible("#cut-view"), true);
  let c = await waitCut(page, s.layers);
  assert.ok(c.line, "a line is set");
  assert.ok(c.layers > s.layers * 0.9, `droplets in ${c.layers} of ${s.layers} layers`);
  const first = await cutPixels(page);
  const firstCut = c;
  // one layer is 0.2 mm: droplets at many distinct heights
  assert.ok(first.rows > 60, `droplet colours on ${first.rows} rows`);

  // moving the line by mouse (drag its end A) changes the cut
  const box = await page.locator("#view").boundingBox();
  const a = await page.evaluate(() => {
    const l = window.dropslice.cut().status().line;
    return l.a;
  });
  const v = (await status(page)).view;
  const ax = box.x + box.width / 2 + (a[0] - v.cx) * v.scale;
  const ay = box.y + box.height / 2 - (a[1] - v.cy) * v.scale;
  await page.mouse.move(ax, ay);
  await page.mouse.down();
  await page.mouse.move(ax + 10, ay + 60, { steps: 5 });
  await page.mouse.up();
  c = await cutStatus(page);
  assert.ok(Math.abs(c.line.a[1] - a[1]) > 1, `end A moved: ${a} -> ${c.line.a}`);
  assert.equal((await status(page)).view.cx, v.cx, "dragging the line does not pan the layer view");
  c = await waitCut(page, s.layers);
  const moved = await cutPixels(page);
  assert.notEqual(moved.image, first.image, "the cut changes when its line moves");
  assert.ok(moved.rows > 60);

  // through the test hook: a line outside the part shows nothing
  assert.equal(await page.evaluate(() => window.dropslice.cut().set({ a: [500, 500], b: [520, 500] })), true);
  c = await waitCut(page, s.layers);
  assert.equal(c.droplets, 0);
  assert.equal(c.voids, 0);
  const empty = await cutPixels(page);
  assert.equal(empty.coloured, 0);
  // refused lines
  assert.equal(await page.evaluate(() => window.dropslice.cut().set({ a: [1, 1], b: [1, 1] })), false);
  assert.equal(await page.evaluate(() => window.dropslice.cut().set({ a: [Number.NaN, 1], b: [1, 1] })), false);

  // voids: a part sliced with fill density 0.8 has voids the core reports, and the cut shows
  // them; with the overlay off they are gone
  await page.fill("#set-fill_density", "0.8");
  await page.click("#btn-slice");
  const s2 = await waitSettled(page, 60_000);
  assert.equal(s2.state, "done");
  await page.evaluate(() => window.dropslice.cut().set({ a: [-1, 10.3], b: [21, 10.3] }));
  c = await waitCut(page, s2.layers);
  assert.ok(c.voids > 100, `${c.voids} voids`);
  const withVoids = await cutPixels(page);
  assert.ok(withVoids.voids > 1000, `${withVoids.voids} void pixels`);
  await page.uncheck("#cut-voids");
  await page.evaluate(() => window.dropslice.cut().redraw());
  const noVoids = await cutPixels(page);
  assert.ok(noVoids.voids < withVoids.voids / 10, `${noVoids.voids} void pixels with the overlay off`);
  await page.check("#cut-voids");

  // the layer shown is kept with the cut, and changing it keeps the line
  await page.evaluate(() => window.dropslice.show(5));
  assert.deepEqual((await cutStatus(page)).line, c.line);
  assert.deepEqual(errors, []);

  // with a cache of 1 MB the page holds few layers: the workers plan the others for the cut
  // and send their droplets near the line; the cut is the same as from the page's cache
  const small = await openPage(env.browser, `${env.url}?cache=1`);
  const s3 = await waitSettled(small.page, 60_000);
  assert.equal(s3.state, "done");
  assert.ok(s3.cached < s3.layers / 2, `${s3.cached} layers cached`);
  await small.page.evaluate((l) => window.dropslice.cut().set(l), firstCut.line);
  const again = await waitCut(small.page, s3.layers);
  assert.equal(again.droplets, firstCut.droplets);
  assert.equal(again.layers, firstCut.layers);
  assert.equal(again.voids, firstCut.voids);
  assert.deepEqual(small.errors, []);
  await small.context.close();
});

// The per-layer plot (www/views/plot.ts): drawn after a slice, a click goes to the layer
// under it, and its label gives the running print time of the core's layer times.
import { after, before, test } from "node:test";
import assert from "node:assert/strict";
import { startWithPage, status, stop, waitSettled } from "./helpers.mjs";

let env;
let main;

before(async () => ({ env, main } = await startWithPage()));

after(() => stop(env));

/** Pixels of the plot's canvas that are not transparent / that are the running-time line's
 *  orange (#d9480f), counted in the page. */
function plotPixels(page) {
  return page.evaluate(() => {
    const c = document.getElementById("plot");
    const d = c.getContext("2d").getImageData(0, 0, c.width, c.height).data;
    let ink = 0;
    let line = 0;
    for (let i = 0; i < d.length; i += 4) {
      if (d[i + 3] > 0) ink++;
      if (d[i + 3] > 200 && d[i] > 190 && d[i + 1] > 50 && d[i + 1] < 110 && d[i + 2] < 50) line++;
    }
    return { ink, line, width: c.width, height: c.height };
  });
}

/** "2 h 10 min" / "3 min 5 s" / "40 s" → seconds (to the precision shown). */
function parseDuration(text) {
  const m = /^(?:(\d+) h )?(?:(\d+) min)? ?(?:(\d+) s)?$/.exec(text.trim());
  assert.ok(m, `not a duration: ${text}`);
  return Number(m[1] ?? 0) * 3600 + Number(m[2] ?? 0) * 60 + Number(m[3] ?? 0);
}

test("after slicing the sample the plot is drawn, a click goes to the layer under it", async () => {
  const { page, errors } = main;
  const s = await waitSettled(page, 60_000);
  assert.equal(s.state, "done");
  assert.ok(s.layers > 50, `layers ${s.layers}`);
  await page.waitForTimeout(300);
  const px = await plotPixels(page);
  assert.ok(px.width > 200 && px.height > 50, JSON.stringify(px));
  assert.ok(px.ink > 0.1 * px.width * px.height, `plot pixels ${JSON.stringify(px)}`);
  assert.ok(px.line > 100, `running-time line pixels ${JSON.stringify(px)}`);

  // the plot area's edges (CSS px) as the plot drew them; the layer under x is found from
  // them here, independently of the page's own mapping
  const box = await page.locator("#plot").boundingBox();
  const { left, right, layers } = await page.evaluate(() => {
    const d = document.getElementById("plot").dataset;
    return { left: Number(d.left), right: Number(d.right), layers: Number(d.layers) };
  });
  assert.equal(layers, s.layers);
  assert.ok(left > 0 && right > left + 100 && right <= box.width, `${left} ${right} ${box.width}`);
  for (const f of [0.13, 0.5, 0.87]) {
    const x = left + f * (right - left);
    await page.mouse.click(box.x + x, box.y + box.height / 2);
    const expected = Math.floor(((x - left) / (right - left)) * s.layers);
    const now = await status(page);
    assert.equal(now.layer, expected, `click at ${f} of the plot`);
    assert.equal(await page.inputValue("#layer"), String(expected), "the slider follows");
  }
  // a drag moves the layer along
  const from = left + 0.2 * (right - left);
  const to = left + 0.6 * (right - left);
  await page.mouse.move(box.x + from, box.y + box.height / 2);
  await page.mouse.down();
  await page.mouse.move(box.x + to, box.y + box.height / 2, { steps: 8 });
  await page.mouse.up();
  assert.equal((await status(page)).layer, Math.floor(((to - left) / (right - left)) * s.layers));
  assert.deepEqual(errors, []);
});

test("the label gives the layer's figures and when it starts, from the core's layer times", async () => {
  const { page } = main;
  // off the plot: the label is the current layer's
  await page.mouse.move(5, 5);
  const first = await status(page);
  const last = first.layers - 1;
  await page.evaluate((i) => window.dropslice.show(i), last);
  await page.waitForTimeout(200);
  const label = await page.locator("#plot-label").innerText();
  const m = new RegExp(`^Layer ${last + 1} · z [\\d.]+ mm · ([\\d,]+) droplets · (.+) to print — layer ${last + 1} starts after (.+)$`).exec(label);
  assert.ok(m, label);
  const droplets = Number(m[1].replace(/,/g, ""));
  const { layerDroplets } = await status(page);
  assert.equal(droplets, layerDroplets.outer + layerDroplets.inner + layerDroplets.fill);
  // the last layer starts after the job's print time less its own time (within the rounding
  // of the text: whole seconds, or minutes above an hour)
  const total = parseDuration(await page.locator("#stat-time").innerText());
  const own = parseDuration(m[2]);
  const startsAfter = parseDuration(m[3]);
  const slack = total >= 3600 ? 61 : 2;
  assert.ok(startsAfter > 0, label);
  assert.ok(Math.abs(startsAfter + own - total) <= slack, `${startsAfter} + ${own} vs ${total}: ${label}`);
  // layer 1 starts at once
  await page.evaluate(() => window.dropslice.show(0));
  await page.waitForTimeout(200);
  assert.match(await page.locator("#plot-label").innerText(), /— layer 1 starts after 0 s$/);
});

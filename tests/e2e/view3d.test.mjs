// The 3D tab (www/views/view3d/view3d.ts, panel.ts) in headless Chromium: WebGL2 renders in
// software here. The canvas' pixels are read back and classified by colour (helpers.mjs
// pixels3d): the part's steel blue, the selected part's accent blue, the cut's orange.
import { after, before, test } from "node:test";
import assert from "node:assert/strict";
import { benchy, clientPoint3d, open3d, pick, pixels3d, startWithPage, stop, waitDone } from "./helpers.mjs";

let env;
let main;

before(async () => {
  ({ env, main } = await startWithPage());
  // CSP violations (three.js must need no eval) are counted from the first page load on
  await main.page.evaluate(() => {
    window.__csp = [];
    document.addEventListener("securitypolicyviolation", (e) => window.__csp.push(`${e.violatedDirective} ${e.blockedURI}`));
  });
});

after(() => stop(env));

/** Clicks Fit once the 3D view's size has settled (the same size on three polls 150 ms apart:
 *  the side plot's height settles after a slice and resizes the canvas, and Fit frames for the
 *  size it sees), then waits for the view to draw a frame after it and reads its pixels. */
async function fitAndDraw(page) {
  const size = () => page.evaluate(() => {
    const s = window.dropslice.view3d();
    const c = document.querySelector("#view3d");
    return `${s.width}x${s.height}/${c.clientWidth}x${c.clientHeight}`;
  });
  let [last, same] = [await size(), 0];
  for (let i = 0; i < 100 && same < 3; i++) {
    await page.waitForTimeout(150);
    const now = await size();
    [last, same] = [now, now === last ? same + 1 : 0];
  }
  const frames = (await page.evaluate(() => window.dropslice.view3d())).frames;
  await page.click("#btn-fit");
  await page.waitForFunction((f) => window.dropslice.view3d().frames > f, frames, { timeout: 10_000 });
  return pixels3d(page);
}

test("3DBenchy in 3D: drawn, cut at the slider's layer, picked by a click, orbited by a drag", async () => {
  const { page, errors } = main;
  await waitDone(page, 60_000);
  await pick(page, benchy);
  const s = await waitDone(page, 240_000);
  assert.equal(s.layers, 240);

  assert.equal(await page.evaluate(() => window.dropslice.view3d()), null, "no WebGL context before the tab is opened");
  // the display mesh is made only for the 3D view shown (the job worker made it ahead of the
  // slice's preparation before)
  assert.equal(await page.evaluate(() => window.dropslice.job().parts[0].mesh), 0, "no display mesh while the 3D view is hidden");
  const chunk = (u) => /\/view3d-[0-9A-Z]+\.js$/.test(u);
  assert.equal((await page.evaluate(() => performance.getEntriesByType("resource").map((e) => e.name))).filter(chunk).length, 0, "the 3D view's code is not loaded before the tab is opened");
  await open3d(page);
  assert.equal((await page.evaluate(() => performance.getEntriesByType("resource").map((e) => e.name))).filter(chunk).length, 1, "the 3D view's code is loaded once the tab is opened");
  await page.waitForFunction(() => window.dropslice.job().parts[0].mesh > 0, null, { timeout: 30_000 });
  assert.equal(await page.isVisible("#view3d canvas"), true);
  assert.equal(await page.isVisible("#legend3d"), true);
  assert.equal(await page.isVisible("#legend"), false);

  // the top layer: the whole boat
  await page.locator("#layer").fill("239");
  const whole = await pixels3d(page);
  assert.deepEqual(whole.state.parts, ["0:0"], "one instance: part 0, copy 0");
  assert.equal(whole.state.slice.current, 239);
  assert.ok(Math.abs(whole.state.slice.top - 48) < 1e-9, `top ${whole.state.slice.top}`);
  assert.ok(whole.width > 400 && whole.height > 400, `canvas ${whole.width}×${whole.height}`);
  assert.ok(whole.part.n > 20_000, `part pixels: ${whole.part.n}`);
  // the part is framed: its pixels' centroid is well inside the canvas
  assert.ok(whole.part.x > whole.width * 0.2 && whole.part.x < whole.width * 0.8, `centroid x ${whole.part.x}`);
  assert.ok(whole.part.y > whole.height * 0.2 && whole.part.y < whole.height * 0.85, `centroid y ${whole.part.y}`);
  assert.ok(whole.background.n > 10_000, "the background shows around the plate");

  // a click on the part selects it (tinted in the accent colour); a click on empty space clears
  assert.ok(whole.part.inner, "a part pixel to click");
  const onPart = await clientPoint3d(page, whole.part.inner.x + 0.5, whole.part.inner.y + 0.5);
  await page.mouse.click(onPart.x, onPart.y);
  assert.equal((await page.evaluate(() => window.dropslice.view3d())).selected, "0:0", "a click on the part selects it");
  const tinted = await pixels3d(page);
  assert.ok(tinted.selected.n > whole.part.n * 0.5, `selected pixels ${tinted.selected.n}`);
  assert.ok(tinted.part.n < whole.part.n * 0.2, `unselected part pixels ${tinted.part.n}`);
  const empty = await clientPoint3d(page, 20, tinted.height - 20);
  await page.mouse.click(empty.x, empty.y);
  assert.equal((await page.evaluate(() => window.dropslice.view3d())).selected, null, "a click on empty space clears");
  assert.ok((await pixels3d(page)).part.n > whole.part.n * 0.9, "the part's own colour again");

  // a drag from empty space orbits: the part moves on the screen; Fit brings the view back.
  // The framing to come back to is Fit's own, taken now: the first framing was made while the
  // page was still laying out (the per-layer plot's height settles after the slice), so under
  // load the canvas may have been resized since.
  const framed = await fitAndDraw(page);
  const from = await clientPoint3d(page, whole.width * 0.85, whole.height * 0.15);
  await page.mouse.move(from.x, from.y);
  await page.mouse.down();
  await page.mouse.move(from.x - 150, from.y + 40, { steps: 6 });
  await page.mouse.up();
  const orbited = await pixels3d(page);
  assert.equal(orbited.state.selected, null, "an orbit is not a click");
  assert.ok(Math.hypot(orbited.part.x - framed.part.x, orbited.part.y - framed.part.y) > 20, "the view turned");
  const fitted = await fitAndDraw(page);
  const sizes = [framed, fitted].map((p) => `${p.width}×${p.height}`);
  assert.ok(Math.hypot(fitted.part.x - framed.part.x, fitted.part.y - framed.part.y) < 2, `Fit restores the framing: ${JSON.stringify([framed.part, fitted.part, fitted.selected, sizes])}`);

  // a low layer: the boat cut at 4 mm (of 48): far fewer part pixels, none high up, a cap
  await page.locator("#layer").fill("19");
  const low = await pixels3d(page);
  assert.equal(low.state.slice.current, 19);
  assert.ok(low.part.n < framed.part.n * 0.7, `part pixels ${low.part.n} vs ${framed.part.n} whole`);
  assert.ok(low.cut.n > 2000, `cut pixels: ${low.cut.n}`);
  // the chimney and the cabin roof are gone: the drawing starts lower on the screen
  assert.ok(low.top > framed.top + 40, `top row ${low.top} vs ${framed.top}`);

  // back to the layer canvas
  await page.click("#mode-layer");
  assert.equal(await page.isVisible("#view3d"), false);
  assert.equal(await page.isVisible("#view"), true);

  assert.deepEqual(await page.evaluate(() => window.__csp), [], "no CSP violation");
  assert.deepEqual(errors, []);
});

test("a .gco file has no mesh: the 3D tab says so", async () => {
  const { page } = main;
  await open3d(page);
  const gco = "; dropslice test\n; layer_height = 0.2 (mm)\n; droplet_aspect = 1.04\nG01 X0 Y0 Z0.2\nG25 X10 Y0\nG26 X10 Y1\n";
  await pick(page, { name: "tiny.gco", mimeType: "text/plain", buffer: Buffer.from(gco) });
  await waitDone(page, 60_000);
  const st = await page.evaluate(() => window.dropslice.view3d());
  assert.deepEqual(st.parts, []);
  assert.equal(st.slice, null);
  assert.equal(await page.isVisible("#view3d-empty"), true);
  await page.click("#mode-layer");
});

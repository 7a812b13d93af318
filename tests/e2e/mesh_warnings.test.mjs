// Mesh diagnostics in the page: an open mesh shows its open edges and the repaired layers; a
// part whose size suggests inches is warned about, not rescaled, and the offered button
// scales it by 25.4 and slices again. Needs dist/ (scripts/build.sh).
import { after, before, test } from "node:test";
import assert from "node:assert/strict";
import { boxStl, pick, startWithPage, status, stop, waitSettled } from "./helpers.mjs";

let env;
let main;

before(async () => ({ env, main } = await startWithPage({ settle: true })));

after(() => stop(env));

/** Opens one STL (a buffer) and waits for its slice; returns the page's status. */
async function open(page, name, buffer) {
  await pick(page, { name, mimeType: "model/stl", buffer });
  return waitSettled(page, 60_000);
}

const warningTexts = (page) => page.$$eval("#warning-list li", (lis) => lis.map((l) => l.textContent));

test("an open mesh: open edges and repaired layers are listed", async () => {
  const { page } = main;
  // one side facet missing: every layer's section is an open chain, closed across the gap
  const s = await open(page, "open-box.stl", boxStl(20, 20, 20, { dropFacet: 4 }));
  assert.equal(s.state, "done");
  assert.ok(s.droplets > 0);
  assert.equal(await page.isVisible("#warnings"), true);
  const w = await warningTexts(page);
  assert.ok(w.some((t) => /the mesh is not closed: \d+ open edges/.test(t)), w.join(" | "));
  assert.ok(w.some((t) => /layers had open sections/.test(t)), w.join(" | "));
  assert.equal(await page.isVisible("#btn-unit-fix"), false);
});

test("a part in inches: warned, not rescaled, fixed by the button", async () => {
  const { page } = main;
  const s = await open(page, "inch-box.stl", boxStl(20 / 25.4, 20 / 25.4, 20 / 25.4));
  assert.equal(s.state, "done");
  assert.match(await page.locator("#stat-size").innerText(), /^0\.8 × 0\.8 × 0\.8 mm/);
  const w = await warningTexts(page);
  assert.ok(w.some((t) => /if the file is in inches, scale it by 25\.4/.test(t)), w.join(" | "));
  assert.equal(await page.isVisible("#btn-unit-fix"), true);
  await page.click("#btn-unit-fix");
  const after = await waitSettled(page, 60_000);
  assert.equal(after.state, "done");
  assert.equal(after.layers, 100);
  assert.match(await page.locator("#stat-size").innerText(), /^20(\.0+)? × 20(\.0+)? × 20(\.0+)? mm/);
  assert.equal(await page.inputValue("#part-scale_x"), "25.4", "the part's scale, in the parts panel");
  assert.equal(await page.isVisible("#btn-unit-fix"), false);
  const status1 = await status(page);
  assert.ok(status1.droplets > 900_000, `${status1.droplets} droplets for the 20 mm cube`);
});

test("a part too thin for any droplet: a clear message, no download, the page stays usable", async () => {
  const { page } = main;
  await page.click("#btn-reset"); // the previous test scaled the part by 25.4
  // a box 0.1 mm wide: thinner than one droplet (B = 0.208 mm)
  const s = await open(page, "sheet.stl", boxStl(0.1, 20, 20));
  assert.equal(s.state, "done");
  assert.equal(s.droplets, 0);
  assert.equal(await page.isVisible("#banner"), true);
  assert.match(await page.locator("#banner").innerText(), /Nothing to print[\s\S]*thinner than the droplet width/);
  assert.equal(await page.isDisabled("#btn-download"), true);
  // the next slice works
  await page.click("#btn-sample");
  const after = await waitSettled(page, 60_000);
  assert.equal(after.state, "done");
  assert.ok(after.droplets > 0);
});

// Makes the pictures of docs/support.md (after scripts/build.sh): 3DBenchy sliced with support
// (support = unit1, the page's switch): a hull layer and the cabin roof layer in the layer view,
// the roof's layer below it with the overhang overlay (support off), and the 3D view with the
// overhang tint. With TWO=1 also a two-material job (two cubes, the second printed by unit 1).
// Usage: [OUT=dir] [TWO=1] node tests/e2e/screenshot-support.mjs
import { mkdtempSync, rmSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { benchy, openPage, pick, repo, start, twoCubesSecondOnUnit, waitDone, waitSettled } from "./helpers.mjs";

const out = process.env.OUT ?? join(repo, "docs/images");
const env = await start();
const tmp = mkdtempSync(join(tmpdir(), "dropslice-shots-"));
try {
  const { page } = await openPage(env.browser, env.url, { width: 1440, height: 900, scale: 1 });
  await waitSettled(page, 60_000);
  const settle = () => waitDone(page, 300_000);
  const shot = async (name) => {
    await page.waitForTimeout(400);
    await page.screenshot({ path: join(out, name) });
    console.log(`wrote ${join(out, name)}`);
  };
  const zoom = async (scale, cx, cy) => page.evaluate((v) => window.dropslice.setView(v), { scale, cx, cy });

  // without support: the roof's overhang marked
  await pick(page, benchy);
  let s = await settle();
  await page.click("#btn-worst-overhang");
  await page.check("#opt-overhangs");
  await page.waitForFunction(() => window.dropslice.status().overhangsMarked !== null, null, { timeout: 60_000 });
  await page.click("#btn-fit");
  await shot("overhang-roof.png");

  // with support
  await page.uncheck("#opt-overhangs");
  await page.check("#opt-support");
  await page.click("#btn-slice");
  s = await settle();
  const roof = s.worstOverhang;
  await page.evaluate((i) => window.dropslice.show(i - 1), roof);
  await page.click("#btn-fit");
  await shot("support-roof.png");
  const per = await page.evaluate(() => window.dropslice.layerUnits());
  let hull = 1;
  for (let i = 1; i < Math.min(per.length, 100); i++) if (per[i][0] > per[hull][0]) hull = i;
  await page.evaluate((i) => window.dropslice.show(i), Number(process.env.HULL ?? hull));
  await page.click("#btn-fit");
  await shot("support-hull.png");
  if (process.env.ZOOM) {
    const [scale, cx, cy] = process.env.ZOOM.split(",").map(Number);
    await zoom(scale, cx, cy);
    await shot("support-hull-zoom.png");
  }
  await page.check("#opt-overhangs");
  await page.click("#mode-3d");
  await page.waitForFunction(() => window.dropslice.view3d()?.overhang != null, null, { timeout: 30_000 });
  await page.evaluate(() => window.dropslice.show(window.dropslice.status().layers - 1));
  await shot("overhang-3d.png");
  await page.click("#mode-layer");
  await page.uncheck("#opt-overhangs");

  if (process.env.TWO) {
    await page.uncheck("#opt-support");
    await twoCubesSecondOnUnit(page, tmp, 1, 300_000);
    await page.click("#btn-slice");
    s = await settle();
    await page.evaluate((i) => window.dropslice.show(i), Math.floor(s.layers / 2));
    await page.click("#mode-layer");
    await page.click("#btn-fit");
    await shot("two-material.png");
  }
} finally {
  await env.close();
  rmSync(tmp, { recursive: true, force: true });
}

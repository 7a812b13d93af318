// Makes docs/screenshot-benchy.png: the page after slicing 3DBenchy.
// Usage: node tests/e2e/screenshot.mjs [layer] (after scripts/build.sh).
// With DETAIL=scale,cx,cy (px/mm, mm) it zooms in and shows the travel moves:
//   DETAIL=70,17,22 SCREENSHOT=docs/screenshot-detail.png node tests/e2e/screenshot.mjs 60
// With VOIDS=1 the void overlay is on (the layer "worst" is the layer with the largest void):
//   VOIDS=1 SCREENSHOT=docs/screenshot-voids.png node tests/e2e/screenshot.mjs worst
// With VIEW3D=1 the stage shows the 3D tab (the part cut at the layer):
//   VIEW3D=1 SCREENSHOT=docs/images/view3d.png node tests/e2e/screenshot.mjs 100
import { join } from "node:path";
import { benchy, openPage, repo, start, waitSettled } from "./helpers.mjs";

const worst = process.argv[2] === "worst";
const layer = worst ? -1 : Number(process.argv[2] ?? 60);
const env = await start();
try {
  const { page } = await openPage(env.browser, env.url, { width: 1440, height: 860, scale: 1 });
  await waitSettled(page, 60_000);
  if (process.env.VOIDS) await page.check("#opt-voids");
  await page.evaluate(() => (document.body.dataset.state = "picking"));
  await page.setInputFiles("#file-input", benchy);
  const s = await waitSettled(page, 240_000);
  if (s.state !== "done") throw new Error(`slice failed: ${s.state}`);
  if (worst) await page.click("#btn-worst");
  else await page.evaluate((l) => window.dropslice.show(l), layer);
  if (process.env.DETAIL) {
    const [scale, cx, cy] = process.env.DETAIL.split(",").map(Number);
    await page.evaluate((v) => window.dropslice.setView(v), { scale, cx, cy });
    await page.check("#opt-travel");
  }
  if (process.env.VIEW3D) await page.click("#mode-3d");
  await page.waitForTimeout(300);
  const out = process.env.SCREENSHOT ?? join(repo, "docs/screenshot-benchy.png");
  await page.screenshot({ path: out });
  const shown = await page.evaluate(() => window.dropslice.status().layer);
  console.log(`wrote ${out} (layer ${shown + 1})`);
} finally {
  await env.close();
}

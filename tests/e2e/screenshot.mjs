// Makes docs/screenshot-benchy.png: the page after slicing 3DBenchy.
// Usage: node tests/e2e/screenshot.mjs [layer] (after scripts/build.sh).
// With DETAIL=scale,cx,cy (px/mm, mm) it zooms in and shows the travel moves:
//   DETAIL=70,17,22 SCREENSHOT=docs/screenshot-detail.png node tests/e2e/screenshot.mjs 60
import { join } from "node:path";
import { benchy, openPage, repo, start, waitSettled } from "./helpers.mjs";

const layer = Number(process.argv[2] ?? 60);
const env = await start();
try {
  const { page } = await openPage(env.browser, env.url, { width: 1440, height: 860, scale: 1 });
  await waitSettled(page, 60_000);
  await page.evaluate(() => (document.body.dataset.state = "picking"));
  await page.setInputFiles("#file-input", benchy);
  const s = await waitSettled(page, 240_000);
  if (s.state !== "done") throw new Error(`slice failed: ${s.state}`);
  await page.evaluate((l) => window.dropslice.show(l), layer);
  if (process.env.DETAIL) {
    const [scale, cx, cy] = process.env.DETAIL.split(",").map(Number);
    await page.evaluate((v) => window.dropslice.setView(v), { scale, cx, cy });
    await page.check("#opt-travel");
  }
  await page.waitForTimeout(300);
  const out = process.env.SCREENSHOT ?? join(repo, "docs/screenshot-benchy.png");
  await page.screenshot({ path: out });
  console.log(`wrote ${out} (layer ${layer + 1})`);
} finally {
  await env.close();
}

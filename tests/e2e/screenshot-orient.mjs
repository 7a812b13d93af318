// Makes docs/images/orient-page.png: the shared U_overhang.obj (upside down) with its Orient
// candidates listed beside the 3D view (after scripts/build.sh).
// Usage: [SCREENSHOT=path] node tests/e2e/screenshot-orient.mjs
import { join } from "node:path";
import { open3d, openPage, pick, screenshotTo, shared, start, waitDone, waitSettled } from "./helpers.mjs";

const env = await start();
try {
  const { page } = await openPage(env.browser, env.url, { width: 1280, height: 800, scale: 1 });
  await waitSettled(page, 60_000);
  await pick(page, join(shared, "models/U_overhang.obj"));
  await waitDone(page, 60_000);
  await open3d(page);
  await page.click("#part-orient");
  await page.waitForSelector("#orient-list .orient-pick", { timeout: 30_000 });
  await page.locator("#orient-box").scrollIntoViewIfNeeded();
  await page.waitForTimeout(500);
  const out = await screenshotTo(page, "docs/images/orient-page.png");
  console.log(`wrote ${out}`);
} finally {
  await env.close();
}

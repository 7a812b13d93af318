// Makes the page's pictures at four window sizes (after scripts/build.sh): a shared model that
// needs support (U_overhang.obj, or MODEL=path) sliced with the support switch on, then the
// page at 1440 × 900 and 1280 × 720 (the window), 800 × 900 and 390 × 844 (the whole page:
// the panels stack and the page scrolls), and the 3D view with the support drawn.
// Usage: [OUT=dir] [MODEL=path] node tests/e2e/screenshot-sizes.mjs
import { join } from "node:path";
import { open3d, openPage, pick, repo, shared, start, waitDone, waitSettled } from "./helpers.mjs";

const out = process.env.OUT ?? join(repo, "docs/images");
const model = process.env.MODEL ?? join(shared, "models/U_overhang.obj");
const env = await start();
try {
  const { page, errors } = await openPage(env.browser, env.url, { width: 1440, height: 900 });
  await waitSettled(page, 60_000);
  await page.check("#opt-support");
  await pick(page, model);
  await waitDone(page, 300_000);
  const worst = await page.evaluate(() => window.dropslice.status().worstOverhang);
  if (worst !== null) await page.evaluate((i) => window.dropslice.show(i + 1), worst);
  const shot = async (name, width, height, fullPage) => {
    await page.setViewportSize({ width, height });
    await page.waitForTimeout(500);
    await page.evaluate(() => window.scrollTo(0, 0));
    await page.click("#btn-fit");
    await page.waitForTimeout(300);
    await page.screenshot({ path: join(out, name), fullPage });
    console.log(`wrote ${join(out, name)}`);
  };
  await shot("page-1440x900.png", 1440, 900, false);
  await shot("page-1280x720.png", 1280, 720, false);
  await shot("page-800x900.png", 800, 900, true);
  await shot("page-390x844.png", 390, 844, true);
  await page.setViewportSize({ width: 1440, height: 900 });
  await open3d(page);
  await page.waitForFunction(() => (window.dropslice.view3d()?.support ?? 0) > 0, null, { timeout: 30_000 });
  await page.waitForTimeout(400);
  await page.screenshot({ path: join(out, "support-3d.png") });
  console.log(`wrote ${join(out, "support-3d.png")}`);
  if (errors.length) console.log(`page errors: ${errors.join("\n")}`);
} finally {
  await env.close();
}

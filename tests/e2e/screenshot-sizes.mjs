// Makes the page's pictures at four window sizes (after scripts/build.sh): a shared model that
// needs support (bridge.obj, or MODEL=path) sliced with the support switch on and the middle
// layer of those with support shown, then the page at 1440 × 900 and 1280 × 720 (the window),
// 800 × 900 and 390 × 844 (the whole page: the panels stack and the page scrolls), and the 3D
// view with the support drawn (zoomed to the part).
// Usage: [OUT=dir] [MODEL=path] node tests/e2e/screenshot-sizes.mjs
import { join } from "node:path";
import { open3d, openPage, pick, pixels3d, repo, shared, start, waitDone, waitSettled } from "./helpers.mjs";

const out = process.env.OUT ?? join(repo, "docs/images");
const model = process.env.MODEL ?? join(shared, "models/bridge.obj");
const env = await start();
try {
  const { page, errors } = await openPage(env.browser, env.url, { width: 1440, height: 900 });
  await waitSettled(page, 60_000);
  await page.check("#opt-support");
  await pick(page, model);
  await waitDone(page, 300_000);
  const per = await page.evaluate(() => window.dropslice.layerUnits());
  const supported = per.map((u, i) => ((u?.[0] ?? 0) > 0 ? i : -1)).filter((i) => i >= 0);
  await page.evaluate((i) => window.dropslice.show(i), supported[Math.floor(supported.length / 2)] ?? 0);
  // the pictures are of the page, not of the passing "… replaced the previous job" notice
  if (await page.isVisible("#undo-close")) await page.click("#undo-close");
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
  // the part to the middle (right-drag pans), then closer (the view zooms to the cursor)
  const px = await pixels3d(page);
  const box = await page.locator("#view3d canvas").boundingBox();
  const at = px.part.n ? px.part : px.selected;
  if (at?.n) {
    const [cx, cy] = [box.x + box.width / 2, box.y + box.height * 0.45];
    await page.mouse.move(box.x + at.x, box.y + at.y);
    await page.mouse.down({ button: "right" });
    // (the pan moves the plate about twice as far as the pointer here: half way)
    await page.mouse.move((cx + box.x + at.x) / 2, (cy + box.y + at.y) / 2, { steps: 10 });
    await page.mouse.up({ button: "right" });
    for (let i = 0; i < 4; i++) await page.mouse.wheel(0, -200);
  }
  await page.waitForTimeout(400);
  await page.screenshot({ path: join(out, "support-3d.png") });
  console.log(`wrote ${join(out, "support-3d.png")}`);
  if (errors.length) console.log(`page errors: ${errors.join("\n")}`);
} finally {
  await env.close();
}

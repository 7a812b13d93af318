// Makes docs/screenshot-benchy.png: the page after slicing 3DBenchy.
// Usage: node tests/e2e/screenshot.mjs [layer] (after scripts/build.sh).
// With DETAIL=scale,cx,cy (px/mm, mm) it zooms in and shows the travel moves:
//   DETAIL=70,17,22 SCREENSHOT=docs/screenshot-detail.png node tests/e2e/screenshot.mjs 60
// With VOIDS=1 the void overlay is on (the layer "worst" is the layer with the largest void):
//   VOIDS=1 SCREENSHOT=docs/screenshot-voids.png node tests/e2e/screenshot.mjs worst
// With VIEW3D=1 the stage shows the 3D tab (the part cut at the layer):
//   VIEW3D=1 SCREENSHOT=docs/images/view3d.png node tests/e2e/screenshot.mjs 100
// With JOB=1 a build job of four files (3DBenchy, extruder_idler_quads.obj, cube_gears.3mf and
// two copies of M3x10_screw.stl), arranged on a 250 × 200 mm plate, in 3D with 3DBenchy selected:
//   JOB=1 SCREENSHOT=docs/images/job3d.png node tests/e2e/screenshot.mjs
import { join } from "node:path";
import { open3d, screenshotTo, shared, slicedPage, start, waitDone } from "./helpers.mjs";

if (process.env.JOB) {
  const env = await start();
  try {
    const files = ["3DBenchy.stl", "extruder_idler_quads.obj", "cube_gears.3mf", "M3x10_screw.stl"].map((f) => join(shared, "models", f));
    const { page } = await slicedPage(env, {
      width: 1440,
      height: 860,
      files,
      // cube_gears' build alone is 168 mm wide: a larger plate than the default 154 × 134 mm
      prepare: async (p) => {
        await p.click("summary:text('Plate')");
        await p.fill("#set-plate_x", "250");
        await p.fill("#set-plate_y", "200");
      },
    });
    // two copies of the screw, then slice the job again
    await page.click(".part-item:nth-child(4)");
    await page.fill("#part-copies", "2");
    await page.press("#part-copies", "Enter");
    await page.waitForFunction(() => window.dropslice.job().layout.instances.length === 5);
    await page.evaluate(() => (document.body.dataset.state = "picking"));
    await page.click("#btn-slice");
    await waitDone(page, 240_000);
    await page.evaluate(() => window.dropslice.show(window.dropslice.status().layers - 1));
    await page.waitForFunction(() => window.dropslice.job().parts.every((p) => p.mesh > 0));
    // 3DBenchy selected: tinted in 3D, its transform in the panel
    await page.click(".part-item:nth-child(1)");
    await page.waitForTimeout(300);
    const out = await screenshotTo(page, "docs/images/job3d.png");
    console.log(`wrote ${out}`);
  } finally {
    await env.close();
  }
  process.exit(0);
}

const worst = process.argv[2] === "worst";
const layer = worst ? -1 : Number(process.argv[2] ?? 60);
const env = await start();
try {
  const { page } = await slicedPage(env, { width: 1440, height: 860, check: process.env.VOIDS ? ["#opt-voids"] : [] });
  if (worst) await page.click("#btn-worst");
  else await page.evaluate((l) => window.dropslice.show(l), layer);
  if (process.env.DETAIL) {
    const [scale, cx, cy] = process.env.DETAIL.split(",").map(Number);
    await page.evaluate((v) => window.dropslice.setView(v), { scale, cx, cy });
    await page.check("#opt-travel");
  }
  if (process.env.VIEW3D) await open3d(page);
  await page.waitForTimeout(300);
  const out = await screenshotTo(page, "docs/screenshot-benchy.png");
  const shown = await page.evaluate(() => window.dropslice.status().layer);
  console.log(`wrote ${out} (layer ${shown + 1})`);
} finally {
  await env.close();
}

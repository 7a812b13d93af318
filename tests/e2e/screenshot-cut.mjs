// Makes docs/images/cut.png: 3DBenchy's vertical cut (after scripts/build.sh).
// Usage: [STAGGER=1] [CUT=ax,ay,bx,by] [ZOOM=scale,t,z] [SCREENSHOT=path] node tests/e2e/screenshot-cut.mjs [layer]
import { screenshotTo, slicedPage, start } from "./helpers.mjs";

const layer = Number(process.argv[2] ?? 60);
const env = await start();
try {
  const { page, s } = await slicedPage(env, { width: 1440, height: 1000, check: process.env.STAGGER ? ["#set-stagger"] : [] });
  await page.evaluate((l) => window.dropslice.show(l), layer);
  await page.click("#btn-cut");
  if (process.env.CUT) {
    const [ax, ay, bx, by] = process.env.CUT.split(",").map(Number);
    await page.evaluate((l) => window.dropslice.cut().set(l), { a: [ax, ay], b: [bx, by] });
  }
  const t0 = Date.now();
  await page.waitForFunction((n) => {
    const c = window.dropslice.cut().status();
    return c.resolved === n && c.pending === 0;
  }, s.layers, { timeout: 240_000, polling: 100 });
  console.log(`cut of ${s.layers} layers in ${Date.now() - t0} ms`);
  if (process.env.ZOOM) {
    const [scale, ct, cz] = process.env.ZOOM.split(",").map(Number);
    await page.evaluate((v) => window.dropslice.cut().setView(v), { scale, ct, cz });
  }
  const d0 = performance.now();
  await page.evaluate(() => window.dropslice.cut().redraw());
  console.log(`draw ${(performance.now() - d0).toFixed(0)} ms (with the round trip)`);
  await page.waitForTimeout(300);
  const out = await screenshotTo(page, "docs/images/cut.png");
  console.log(`wrote ${out}`, JSON.stringify({ ...(await page.evaluate(() => window.dropslice.cut().status())), view: 0 }));
} finally {
  await env.close();
}

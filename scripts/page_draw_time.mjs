// The layer canvas' draw in the page (www/views/canvas/render.ts): slices a model (3DBenchy by
// default) in headless Chromium, then draws the layer shown RUNS times (default 7), each time
// at a view moved by a fraction of a pixel so nothing is reused, and prints the median and the
// largest time of the whole draw (synchronous, `dropslice.redraw()`) and up to the next frame
// (the browser's rasterisation and compositing included). Usage:
//   node scripts/page_draw_time.mjs [MODEL] [SCALE]     (SCALE: px/mm; default the fitted view)
// Needs `bash scripts/build.sh` first.
import { benchy, openPage, start, waitSettled } from "../tests/e2e/helpers.mjs";

const file = process.argv[2] || benchy;
const scale = Number(process.argv[3]) || null;
const runs = Math.max(1, Number(process.env.RUNS ?? 7) | 0);
const env = await start();
try {
  const { page } = await openPage(env.browser, env.url);
  await waitSettled(page);
  await page.setInputFiles("#file-input", file);
  const s = await waitSettled(page, 600_000);
  if (s.state !== "done") throw new Error(`${file}: the page ended in state ${s.state}`);
  const times = await page.evaluate(
    async ([runs, scale]) => {
      const ds = window.dropslice;
      const v = ds.status().view;
      const out = [];
      for (let i = 0; i <= runs; i++) {
        ds.setView({ scale: scale ?? v.scale, cx: v.cx + i * 1e-3, cy: v.cy });
        const t0 = performance.now();
        ds.redraw();
        const t1 = performance.now();
        await new Promise((ok) => requestAnimationFrame(() => setTimeout(ok, 0)));
        if (i > 0) out.push([t1 - t0, performance.now() - t0]); // the first one warms up
      }
      return out;
    },
    [runs, scale],
  );
  const stat = (xs) => {
    const s = [...xs].sort((a, b) => a - b);
    return `median ${s[(s.length - 1) >> 1].toFixed(1)} ms, largest ${s[s.length - 1].toFixed(1)} ms`;
  };
  console.log(`${file}: layer ${s.layer + 1}, ${s.layerDroplets ? Object.values(s.layerDroplets).reduce((a, b) => a + b, 0) : "?"} droplets`);
  console.log(`draw (synchronous): ${stat(times.map((t) => t[0]))}`);
  console.log(`draw to the next frame: ${stat(times.map((t) => t[1]))}`);
} finally {
  await env.close();
}

// Times the page's part figures with the Voids overlay on: 3DBenchy (or the files given) is
// sliced with analysis, `status().seconds` from the file chosen to every layer sliced and
// analysed. Usage: node scripts/page_voids_time.mjs [RUNS] [MODEL.stl ...]; another build of
// the page with DROPSLICE_DIST=DIR (tests/e2e/helpers.mjs). A warm-up run, then RUNS timed.
import { start, timeVisits, waitSettled, benchy } from "../tests/e2e/helpers.mjs";

const runs = Number(process.argv[2] ?? 5);
const files = process.argv.length > 3 ? process.argv.slice(3) : [benchy];
// VOIDS=0: the overlay off (the slicing alone, for comparison).
const voids = process.env.VOIDS !== "0";
const env = await start();
try {
  for (const f of files) {
    const times = await timeVisits(env, runs, async (page, i) => {
      if (voids) {
        await page.check("#opt-voids");
        await waitSettled(page); // the sample part analysed
      }
      await page.setInputFiles("#file-input", f);
      await page.waitForFunction(() => document.body.dataset.state === "slicing", null, { timeout: 120_000 }).catch(() => {});
      await page.waitForFunction((voids) => {
        const st = window.dropslice.status();
        return st.state !== "slicing" && (!voids || st.analysed === st.layers);
      }, voids, { timeout: 600_000, polling: 50 });
      const s = await page.evaluate(() => window.dropslice.status());
      if (s.state !== "done") throw new Error(`${f}: page state ${s.state}`);
      console.log(`${f.split("/").pop()} run ${i}${i ? "" : " (warm-up)"}: ${s.seconds.toFixed(2)} s, ${s.analysed}/${s.layers} layers analysed, ${s.workers} worker(s)`);
      return s.seconds;
    });
    times.sort((a, b) => a - b);
    console.log(`${f.split("/").pop()}: best ${times[0].toFixed(2)} s, median ${times[times.length >> 1].toFixed(2)} s`);
  }
} finally {
  await env.close();
}

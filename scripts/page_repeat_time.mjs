// A page's first slice of a model against its next ones (docs/performance.md, "The
// page's time, request by request"): in each of PAGES fresh pages, after the sample part, MODEL is chosen SLICES times in
// a row; the page's own clock (file chosen → every layer's code ready) of each slice is
// printed. The first slice runs while the engine still compiles the code the model needs;
// the next ones run compiled code. Usage, after `bash scripts/build.sh`:
//   node scripts/page_repeat_time.mjs [MODEL] [SLICES] [PAGES]   (DROPSLICE_DIST=DIR for another build)
// PROFILE=1 prints each slice's per-stage profile too (core/stages.ts: ms summed over the page
// and its workers; a "longest call" line is the longest of the workers' calls of that kind).
import { dirname, join, resolve } from "node:path";
import { fileURLToPath } from "node:url";

const repo = resolve(dirname(fileURLToPath(import.meta.url)), "..");
const { start, openPage, waitSettled } = await import(join(repo, "tests/e2e/helpers.mjs"));
const model = process.argv[2] || join(repo, "../shared/models/3DBenchy.stl");
const count = (arg, fallback) => {
  const n = Number(arg ?? fallback);
  if (!Number.isInteger(n) || n < 1 || n > 50) throw new Error(`expected a count from 1 to 50, got ${arg}`);
  return n;
};
const slices = count(process.argv[3], 3);
const pages = count(process.argv[4], 3);
const profile = process.env.PROFILE === "1";

const env = await start();
try {
  for (let p = 0; p < pages; p++) {
    const { page, context } = await openPage(env.browser, env.url);
    try {
      await waitSettled(page); // the sample part
      const times = [];
      for (let k = 0; k < slices; k++) {
        await page.evaluate(() => (document.body.dataset.state = "picking"));
        if (profile) {
          await page.evaluate(() => globalThis.__dropsliceStages?.reset());
          for (const wk of page.workers()) await wk.evaluate(() => globalThis.__dropsliceStages?.reset()).catch(() => {});
        }
        await page.setInputFiles("#file-input", model);
        const s = await waitSettled(page, 900_000);
        if (s.state !== "done") throw new Error(`the page ended in state ${s.state}`);
        times.push(s.seconds.toFixed(3));
        if (profile) {
          const all = [await page.evaluate(() => globalThis.__dropsliceStages?.read() ?? {})];
          for (const wk of page.workers()) all.push((await wk.evaluate(() => globalThis.__dropsliceStages?.read() ?? null).catch(() => null)) ?? {});
          const sum = {};
          for (const st of all) for (const [k, v] of Object.entries(st)) sum[k] = /longest/.test(k) ? Math.max(sum[k] ?? 0, v) : (sum[k] ?? 0) + v;
          const line = Object.entries(sum).sort(([a], [b]) => a.localeCompare(b)).map(([k, v]) => `${k} ${v.toFixed(1)}`).join("; ");
          console.log(`  page ${p + 1} slice ${k + 1} (${s.seconds.toFixed(3)} s): ${line}`);
        }
      }
      console.log(`page ${p + 1}: ${times.join(" s, ")} s`);
    } finally {
      await context.close();
    }
  }
} finally {
  await env.close();
}

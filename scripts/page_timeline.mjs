// The page's requests to its workers while it slices a model, and the CPU time of every
// Chromium thread meanwhile (docs/performance.md, "The page's time, request by request").
// Each message the page sends to or receives from a worker is logged on the page's thread
// (a `Worker` wrapper installed before the page's script runs), in ms from the file chosen;
// the layers' batches are left out. Usage, after `bash scripts/build.sh`:
//   node scripts/page_timeline.mjs [MODEL] [RUNS]   (DROPSLICE_DIST=DIR times another build)
// The CPU per thread is read from /proc (Linux).
import { readFileSync, readdirSync } from "node:fs";
import { dirname, join, resolve } from "node:path";
import { fileURLToPath } from "node:url";

const repo = resolve(dirname(fileURLToPath(import.meta.url)), "..");
const { start, openPage, waitSettled, recordWorkerMessages, workerLog, clearWorkerLog } = await import(join(repo, "tests/e2e/helpers.mjs"));
const model = process.argv[2] || join(repo, "../shared/models/3DBenchy.stl");
const runs = Number(process.argv[3] ?? 2);
// PAUSE_MS: wait this long after the sample part settles before choosing the file (as a user
// takes a while to), printing the CPU of that pause.
const pause = Number(process.env.PAUSE_MS ?? 0);

/** The CPU (ms) every thread used from `before` to `after` (`cpuByThread`), summed and the largest. */
function summary(before, after) {
  const rows = Object.entries(after)
    .map(([k, v]) => [k, (v - (before[k] ?? 0)) * 10])
    .filter(([, v]) => v > 0)
    .sort((a, b) => b[1] - a[1]);
  return `${rows.reduce((a, [, v]) => a + v, 0)} ms in all; ${rows.slice(0, 8).map(([k, v]) => `${k} ${v}`).join(", ")}`;
}

/** CPU ticks (1/100 s) of every Chromium thread, by process type and thread name. */
function cpuByThread() {
  const out = {};
  for (const pid of readdirSync("/proc").filter((p) => /^\d+$/.test(p))) {
    let cmd;
    let tasks;
    try {
      cmd = readFileSync(`/proc/${pid}/cmdline`, "utf8");
      if (!/chrom/i.test(cmd)) continue;
      tasks = readdirSync(`/proc/${pid}/task`);
    } catch {
      continue;
    }
    const type = (/--type=([\w-]+)/.exec(cmd) || [, "browser"])[1];
    for (const t of tasks) {
      try {
        const stat = readFileSync(`/proc/${pid}/task/${t}/stat`, "utf8");
        const name = readFileSync(`/proc/${pid}/task/${t}/comm`, "utf8").trim().replace(/\d+$/, "#");
        const f = stat.slice(stat.lastIndexOf(")") + 2).split(" ");
        const key = `${type}: ${name}`;
        out[key] = (out[key] ?? 0) + Number(f[11]) + Number(f[12]);
      } catch {
        // the thread ended meanwhile
      }
    }
  }
  return out;
}

const env = await start();
try {
  for (let r = 0; r < runs; r++) {
    const { page, context } = await openPage(env.browser, env.url);
    try {
      await recordWorkerMessages(page);
      await page.reload();
      await waitSettled(page); // the sample part
      if (pause > 0) {
        const quiet = cpuByThread();
        await new Promise((r) => setTimeout(r, pause));
        console.log(`  CPU in the ${pause} ms pause after the sample part: ${summary(quiet, cpuByThread())}`);
      }
      await clearWorkerLog(page);
      const before = cpuByThread();
      await page.setInputFiles("#file-input", model);
      const s = await waitSettled(page, 900_000);
      const after = cpuByThread();
      const log = await workerLog(page);
      const t0 = log.length ? log[0][0] : 0;
      console.log(`run ${r + 1}: every layer's code ready after ${s.seconds.toFixed(2)} s (the page's clock); requests in ms from the first one sent:`);
      for (const [t, w, dir, kind, id, from] of log) {
        if (kind === "figures") continue;
        console.log(`  ${(t - t0).toFixed(0).padStart(6)}  worker ${w + 1} ${dir} ${kind} #${id}${from !== "" ? ` from ${from}` : ""}`);
      }
      console.log(`  CPU while slicing: ${summary(before, after)}`);
    } finally {
      await context.close();
    }
  }
} finally {
  await env.close();
}

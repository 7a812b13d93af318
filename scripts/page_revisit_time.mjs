// Visits of one browser profile (docs/performance.md, "The module, compiled once"): VISITS
// times a new page of the same profile opens the app, waits for the sample part and slices
// MODEL once; each visit prints how the module's request was answered (status, from the HTTP
// cache or the service worker), the page's compile of the module (ms, `performance.measure`
// "dropslice: compile") and the slice's time (the page's own clock). The engine's code cache
// applies when a later visit's compile is much shorter than the first's.
// Usage, after `bash scripts/build.sh`:
//   node scripts/page_revisit_time.mjs [MODEL] [VISITS]
//   SW=0: service workers blocked (the HTTP cache and the server's 304s alone);
//   DROPSLICE_DIST=DIR for another build.
import { mkdtempSync, rmSync } from "node:fs";
import { tmpdir } from "node:os";
import { dirname, join, resolve } from "node:path";
import { fileURLToPath } from "node:url";
import { chromium } from "playwright-core";

const repo = resolve(dirname(fileURLToPath(import.meta.url)), "..");
const { chromiumPath } = await import(join(repo, "tests/e2e/helpers.mjs"));
const { serve } = await import(join(repo, "scripts/serve.mjs"));
const model = process.argv[2] || join(repo, "../shared/models/3DBenchy.stl");
const visits = Number(process.argv[3] ?? 3);
if (!Number.isInteger(visits) || visits < 1 || visits > 20) throw new Error(`expected 1 to 20 visits, got ${process.argv[3]}`);
const sw = process.env.SW !== "0";

const dist = resolve(process.env.DROPSLICE_DIST ?? join(repo, "dist"));
const { server, url } = await serve(dist, 0);
/** The server's answers to the module's requests since the last visit's line. */
let served = [];
server.on("request", (req, res) => {
  if (/dropslice_bg\.wasm/.test(req.url ?? "")) res.on("finish", () => served.push(res.statusCode));
});
const profile = mkdtempSync(join(tmpdir(), "dropslice-profile-"));
const context = await chromium.launchPersistentContext(profile, {
  executablePath: chromiumPath,
  headless: true,
  serviceWorkers: sw ? "allow" : "block",
  args: ["--headless", "--no-sandbox", "--disable-gpu", "--no-first-run", "--disable-background-networking", "--disable-component-update", "--disable-sync"],
});
try {
  for (let v = 1; v <= visits; v++) {
    const page = await context.newPage();
    const answers = [];
    page.on("response", (r) => {
      if (/dropslice_bg\.wasm/.test(r.url())) answers.push(`${r.status()}${r.fromServiceWorker() ? " from the service worker" : ""}`);
    });
    page.on("requestfinished", async (r) => {
      if (!/dropslice_bg\.wasm/.test(r.url())) return;
      const t = r.timing();
      if (t.responseStart >= 0 && t.responseEnd - t.requestStart < 1) answers.push("(HTTP cache)");
    });
    await page.goto(url);
    await page.waitForFunction(() => ["done", "error"].includes(document.body.dataset.state ?? ""), null, { timeout: 120_000 });
    const compile = await page.evaluate(() => performance.getEntriesByName("dropslice: compile").map((e) => e.duration));
    await page.evaluate(() => (document.body.dataset.state = "picking"));
    await page.setInputFiles("#file-input", model);
    await page.waitForFunction(() => ["done", "error", "cancelled"].includes(document.body.dataset.state ?? ""), null, { timeout: 900_000 });
    const s = await page.evaluate(() => window.dropslice.status());
    console.log(`visit ${v}: module ${answers.join(", ") || "no request"} (the server answered ${served.join(", ") || "nothing"}); compile ${compile.map((ms) => ms.toFixed(0)).join(", ")} ms; slice ${s.state} ${s.seconds?.toFixed(3)} s`);
    // the service worker installs after the first load; give the code cache time to be written
    await page.waitForTimeout(3000);
    await page.close();
    served = [];
  }
} finally {
  await context.close();
  await new Promise((ok) => server.close(ok));
  rmSync(profile, { recursive: true, force: true });
}

// Shared helpers of the browser tests: a static server for dist/, Debian's Chromium through
// playwright-core, paths of the shared models, opening files and waiting for their slice, the
// download, the pixels of the layer canvas and of the 3D view, test meshes, and a G-code parser
// for comparisons.
import assert from "node:assert/strict";
import { createHash } from "node:crypto";
import { existsSync, readFileSync, rmSync, writeFileSync } from "node:fs";
import { dirname, join, resolve } from "node:path";
import { after, before } from "node:test";
import { fileURLToPath } from "node:url";
import { chromium } from "playwright-core";
import { serve } from "../../scripts/serve.mjs";

export const repo = resolve(dirname(fileURLToPath(import.meta.url)), "../..");
export const shared = resolve(process.env.DROPSLICE_SHARED ?? join(repo, "../shared"));
export const benchy = join(shared, "models/3DBenchy.stl");
export const chromiumPath = process.env.CHROMIUM ?? "/usr/bin/chromium";
/** The shared 20 mm cube (small enough to embed in a link) and its sha-256 in hex. */
export const cube = readFileSync(join(shared, "models/cube_20mm_ascii.stl"));
export const cubeSha = createHash("sha256").update(cube).digest("hex");
/** Bytes in base64url, as links carry them. */
export const b64url = (buf) => Buffer.from(buf).toString("base64url");

/** Starts the server and the browser; returns { url, browser, close }. */
export async function start() {
  // DROPSLICE_DIST serves another build of the page (e.g. one made aside while dist/ is rebuilt)
  const dist = resolve(process.env.DROPSLICE_DIST ?? join(repo, "dist"));
  if (!existsSync(join(dist, "index.html"))) throw new Error(`${dist} is missing: run scripts/build.sh first`);
  const { server, url } = await serve(dist, 0);
  const browser = await launchBrowser();
  return {
    url,
    browser,
    async close() {
      await browser.close().catch(() => {});
      await new Promise((ok) => server.close(ok));
    },
  };
}

/** start() for the tests of one file: started before them, closed after them. The object it
 *  returns gets start()'s { url, browser, close } once the tests begin. */
export function startForTests() {
  const env = {};
  before(async () => Object.assign(env, await start()));
  after(async () => env.close?.());
  return env;
}

/** start() and the page most of a test file's tests share; with `settle`, once its sample
 *  part is sliced. For `before(async () => ({ env, main } = await startWithPage()))`. */
export async function startWithPage({ settle = false } = {}) {
  const env = await start();
  const main = await openPage(env.browser, env.url);
  if (settle) await waitSettled(main.page, 60_000);
  return { env, main };
}

/** Closes what start() opened (if it got that far) and removes temporary directories. */
export async function stop(env, ...dirs) {
  await env?.close();
  for (const d of dirs) rmSync(d, { recursive: true, force: true });
}

/** Debian's Chromium, headless. */
export function launchBrowser() {
  // playwright gives every launch a fresh, empty user-data-dir of its own
  return chromium.launch({
    executablePath: chromiumPath,
    headless: true,
    args: [
      "--headless",
      "--no-sandbox",
      "--disable-gpu",
      "--disable-quic",
      "--no-first-run",
      "--disable-background-networking",
      "--disable-component-update",
      "--disable-sync",
    ],
  });
}

/** A new page that collects page errors and console errors in `errors`, for the test to check;
 *  with `csp`, also Content-Security-Policy violations in window.__csp. */
export async function openPage(browser, url, { width = 1440, height = 900, scale = 1, csp = false } = {}) {
  const context = await browser.newContext({ viewport: { width, height }, deviceScaleFactor: scale, acceptDownloads: true });
  if (csp) {
    await context.addInitScript(() => {
      window.__csp = [];
      document.addEventListener("securitypolicyviolation", (e) => window.__csp.push(`${e.violatedDirective} ${e.blockedURI}`));
    });
  }
  const page = await context.newPage();
  const errors = [];
  page.on("pageerror", (e) => errors.push(String(e)));
  page.on("console", (m) => {
    if (m.type() === "error") errors.push(m.text());
  });
  await page.goto(url);
  return { page, context, errors };
}

/** Installs, before the page's script runs (from its next load on), a `Worker` wrapper that
 *  logs every message the page posts to a worker ("→") and every one it receives from a worker
 *  ("←"; the layers' batches left out) as [ms, worker, direction, kind, id, from], workers
 *  numbered from 0 as they are made; `workerLog` reads the log since `clearWorkerLog`. */
export async function recordWorkerMessages(page) {
  await page.addInitScript(() => {
    const Base = window.Worker;
    let n = 0;
    window.__workerLog = [];
    const log = (worker, dir, m) => window.__workerLog.push([performance.now(), worker, dir, m?.kind, m?.id, m?.data?.from ?? ""]);
    window.Worker = class extends Base {
      constructor(...args) {
        super(...args);
        const worker = n++;
        const post = this.postMessage.bind(this);
        this.postMessage = (m, t) => {
          log(worker, "→", m);
          return post(m, t);
        };
        this.addEventListener("message", (e) => {
          if (e.data?.kind !== "layers") log(worker, "←", e.data);
        });
      }
    };
  });
}

export const workerLog = (page) => page.evaluate(() => window.__workerLog);
export const clearWorkerLog = (page) => page.evaluate(() => void (window.__workerLog = []));

/** For the screenshot scripts: a page of `width` × `height` that has settled on the sample,
 *  then ticked the checkboxes `check` (selectors), had `prepare(page)` done and sliced `files`
 *  (3DBenchy unless given); returns the page and the status once done. */
export async function slicedPage(env, { width, height, files = benchy, check = [], prepare = async () => {} }) {
  const { page } = await openPage(env.browser, env.url, { width, height, scale: 1 });
  await waitSettled(page, 60_000);
  for (const selector of check) await page.check(selector);
  await prepare(page);
  // what a box or setting set off on the sample (the voids analysis) ends before the pick
  await waitSettled(page, 60_000);
  await pick(page, files);
  return { page, s: await waitDone(page, 240_000) };
}

export const status = (page) => page.evaluate(() => window.dropslice.status());

/** Saves the page's picture at $SCREENSHOT, else at `path` in the repository; returns where. */
export async function screenshotTo(page, path) {
  const out = process.env.SCREENSHOT ?? join(repo, path);
  await page.screenshot({ path: out });
  return out;
}

/** Waits until the page has finished a slice (or failed); returns its status. */
export async function waitSettled(page, timeout = 240_000) {
  await page.waitForFunction(
    () => ["done", "error", "cancelled"].includes(document.body.dataset.state ?? ""),
    null,
    { timeout, polling: 100 },
  );
  return status(page);
}

/** For the timing scripts: from now on, the page's long tasks (over 50 ms on its main thread:
 *  a `PerformanceObserver` for `longtask`) and the longest gap between ticks of a 16 ms timer
 *  (a coarser check of the same); a user-timing mark "dropslice:watched" says when (for a
 *  trace), and the page's state is set to "picking" (waitSettled then waits for what comes).
 *  [[longTasks]] stops them and returns what they saw. */
export async function watchLongTasks(page) {
  await page.evaluate(() => {
    performance.mark("dropslice:watched");
    const w = (window.__longTasks = { tasks: [], gap: 0, last: performance.now(), from: performance.now() });
    w.observer = new PerformanceObserver((list) => {
      for (const e of list.getEntries()) w.tasks.push([e.startTime, e.duration]);
    });
    w.observer.observe({ type: "longtask" });
    w.timer = setInterval(() => {
      const now = performance.now();
      w.gap = Math.max(w.gap, now - w.last);
      w.last = now;
    }, 16);
    document.body.dataset.state = "picking";
  });
}

/** Stops [[watchLongTasks]]' watch: { tasks: [[start, duration]] (ms; start from the watch),
 *  gap (ms) }. */
export function longTasks(page) {
  return page.evaluate(() => {
    const b = window.__longTasks;
    clearInterval(b.timer);
    b.observer.disconnect();
    return { tasks: b.tasks.filter(([t]) => t >= b.from).map(([t, d]) => [t - b.from, d]), gap: b.gap };
  });
}

/**
 * Times `file` in the page (for the timing scripts): a warm-up visit and `runs` timed ones,
 * each in a new page whose sample part has settled. `visit(page, i)` (i = 0: the warm-up)
 * does the work and returns its seconds; returns the timed visits' seconds.
 */
export async function timeVisits(env, runs, visit) {
  const times = [];
  for (let i = 0; i <= runs; i++) {
    const { page, context } = await openPage(env.browser, env.url);
    await waitSettled(page); // the sample part of the first visit
    const seconds = await visit(page, i);
    if (i > 0) times.push(seconds);
    await context.close();
  }
  return times;
}

/** The page answers page.evaluate within 2 s, `times` times in a row (150 ms apart). */
export async function answers(page, times = 1) {
  for (let i = 0; i < times; i++) {
    if (i > 0) await page.waitForTimeout(150);
    const answer = await Promise.race([page.evaluate(() => 1), new Promise((ok) => setTimeout(() => ok("timeout"), 2000))]);
    assert.equal(answer, 1, `the page did not answer within 2 s (poll ${i + 1} of ${times})`);
  }
}

/** Waits until the page's state is one of `states` (by default: a slice done or failed, or
 *  waiting for a file), asserting all the while that it answers; returns its status. */
export async function settleAnswering(page, { timeout = 60_000, states = ["done", "error", "cancelled", "idle"] } = {}) {
  const t0 = Date.now();
  for (;;) {
    await answers(page);
    const s = await status(page);
    if (states.includes(s.state)) return s;
    if (Date.now() - t0 > timeout) assert.fail(`the page did not settle: ${JSON.stringify(s)}`);
    await page.waitForTimeout(100);
  }
}

/** Opens files with the page's file input: paths, or { name, mimeType, buffer }. The page's
 *  state is set to "picking" first, so that waitSettled / waitDone wait for this slice. */
export async function pick(page, files) {
  await page.evaluate(() => (document.body.dataset.state = "picking"));
  await page.setInputFiles("#file-input", files);
}

/** Waits for the slice and asserts that it finished (state "done"; else the banner says why);
 *  returns the page's status. */
export async function waitDone(page, timeout = 240_000) {
  const s = await waitSettled(page, timeout);
  const banner = s.state === "done" ? "" : await page.locator("#banner").innerText().catch(() => "");
  assert.equal(s.state, "done", `page state ${s.state}: ${banner}`);
  return s;
}

/** A two-material job: two copies of the 20 mm cube (written into `dir` as cube-a.stl and
 *  cube-b.stl) opened and sliced, then the second part given to discharge unit `unit` in the
 *  parts panel. The job is not sliced again: the caller clicks Slice. */
export async function twoCubesSecondOnUnit(page, dir, unit, timeout = 240_000) {
  const files = ["cube-a.stl", "cube-b.stl"].map((n) => join(dir, n));
  for (const f of files) writeFileSync(f, cube);
  await pick(page, files);
  await waitDone(page, timeout);
  await page.click(".part-item:nth-child(2)");
  await page.selectOption("#part-unit", String(unit));
  await page.waitForFunction((u) => window.dropslice.job().parts[1].unit === u, unit);
}

/** Opens a share link that does not embed its model (too big): the new page asks for the file,
 *  naming it (`named`, a RegExp). Returns openPage()'s { page, context, errors }. */
export async function openLinkAskingForFile(browser, url, named) {
  assert.doesNotMatch(url, /&m=/, "the model is too big to embed");
  const other = await openPage(browser, url);
  await other.page.waitForFunction(() => !document.getElementById("link-note").hidden);
  assert.match(await other.page.locator("#link-note").innerText(), named);
  return other;
}

/** The text of the .gco that the Download button gives. */
export async function downloadText(page) {
  const [download] = await Promise.all([page.waitForEvent("download"), page.click("#btn-download")]);
  return readFileSync(await download.path(), "utf8");
}

/** Clicks "Copy preview link" and reads the link from the dialog. */
export async function shareLink(page) {
  await page.click("#btn-share");
  await page.waitForSelector("#share-dialog[open]");
  const url = await page.inputValue("#share-url");
  await page.click("#share-dialog button");
  await page.waitForSelector("#share-dialog:not([open])", { state: "attached" });
  return url;
}

/** Opens the 3D tab and waits until its view is made (its code, three.js, is a chunk the page
 *  loads the first time the tab is opened); returns the view's state. */
export async function open3d(page, timeout = 30_000) {
  await page.click("#mode-3d");
  return view3dReady(page, timeout);
}

/** Waits until the 3D view is made (the tab was opened, by a click or by the page itself, and
 *  its code is in); returns the view's state. */
export async function view3dReady(page, timeout = 30_000) {
  await page.waitForFunction(() => window.dropslice.view3d() !== null, null, { timeout, polling: 100 });
  return page.evaluate(() => window.dropslice.view3d());
}

/** Draws the 3D view now and classifies the pixels of its WebGL canvas (device pixels; the
 *  view keeps its drawing buffer), each pixel in the first class it fits: the selected part's
 *  accent blue, the other parts' steel blue, the cut's orange, the background. Per class its
 *  count n and centroid x, y; for parts and the selected part also `inner`: the pixel of the
 *  class nearest the centroid with pixels of the class 4 px around it (to click or grab; null
 *  if none). Also the view's state, the
 *  canvas' size, `top` (the highest row of part, selected or cut pixels) and `tint` (the number
 *  of pixels of the overhang tint, magenta-red and dim, counted apart from the classes). */
export function pixels3d(page) {
  return page.evaluate(() => {
    const state = window.dropslice.view3d();
    const c = document.querySelector("#view3d canvas");
    const t = document.createElement("canvas");
    t.width = c.width;
    t.height = c.height;
    const g = t.getContext("2d");
    g.drawImage(c, 0, 0);
    const d = g.getImageData(0, 0, t.width, t.height).data;
    const classOf = (i) => {
      const r = d[i], gr = d[i + 1], b = d[i + 2];
      if (b - r > 120 && r < 90) return "selected";
      if (b - r > 40 && b > gr) return "part";
      if (r - b > 80 && r > 180) return "cut";
      if (Math.abs(r - 0xee) < 4 && Math.abs(gr - 0xf1) < 4 && Math.abs(b - 0xf5) < 4) return "background";
      return null;
    };
    const cls = { part: [0, 0, 0], selected: [0, 0, 0], cut: [0, 0, 0], background: [0, 0, 0] };
    let top = t.height;
    let tint = 0;
    for (let i = 0, p = 0; i < d.length; i += 4, p++) {
      if (d[i] > d[i + 2] + 15 && d[i + 2] > d[i + 1] + 30) tint++;
      const k = classOf(i);
      if (k === null) continue;
      const x = p % t.width, y = (p / t.width) | 0;
      cls[k][0]++;
      cls[k][1] += x;
      cls[k][2] += y;
      if (k !== "background" && y < top) top = y;
    }
    const out = { state, width: t.width, height: t.height, top, tint };
    const R = 4;
    const is = (k, x, y) => classOf(4 * (y * t.width + x)) === k;
    for (const [k, [n, sx, sy]] of Object.entries(cls)) {
      const e = { n, x: n ? sx / n : NaN, y: n ? sy / n : NaN, inner: null };
      if (n && (k === "part" || k === "selected")) {
        let best = null;
        for (let y = R; y < t.height - R; y++) {
          for (let x = R; x < t.width - R; x++) {
            if (!(is(k, x, y) && is(k, x - R, y) && is(k, x + R, y) && is(k, x, y - R) && is(k, x, y + R))) continue;
            const dist = Math.hypot(x - e.x, y - e.y);
            if (!best || dist < best.dist) best = { x, y, dist };
          }
        }
        e.inner = best;
      }
      out[k] = e;
    }
    return out;
  });
}

/** Client coordinates of a device pixel of the 3D view's canvas. */
export async function clientPoint3d(page, px, py) {
  const r = await page.locator("#view3d canvas").boundingBox();
  const dims = await page.evaluate(() => {
    const c = document.querySelector("#view3d canvas");
    return { w: c.width, h: c.height };
  });
  return { x: r.x + (px * r.width) / dims.w, y: r.y + (py * r.height) / dims.h };
}

/** Number of canvas pixels whose colour passes `test` (a JS expression over r, g, b). The
 *  expression goes in the evaluated source (run by the DevTools protocol): a `new Function`
 *  inside the page would be refused by its Content-Security-Policy (no 'unsafe-eval'). */
export function countPixels(page, test) {
  return page.evaluate(`(() => {
    const pass = (r, g, b) => (${test});
    const c = document.getElementById("view");
    const d = c.getContext("2d").getImageData(0, 0, c.width, c.height).data;
    let n = 0;
    for (let i = 0; i < d.length; i += 4) if (pass(d[i], d[i + 1], d[i + 2])) n++;
    return n;
  })()`);
}

/** Coloured (non-background, non-grid) pixels of the canvas: the droplets drawn. */
export const inkPixels = (page) => countPixels(page, "Math.max(r, g, b) - Math.min(r, g, b) > 60");

/** Canvas pixels in the void overlay's magenta. */
export const voidPixels = (page) => countPixels(page, "r > 150 && b > 90 && g < 110 && r - g > 80 && b - g > 30");

/** Pixels of the canvas as a data URL (changes whenever anything drawn changes). */
export const canvasPixels = (page) => page.evaluate(() => document.getElementById("view").toDataURL("image/png"));

/** Commands of a .gco text: [{code, x, y, z}] (comments dropped). */
export function parseGcode(text) {
  const out = [];
  for (const raw of text.split("\n")) {
    const line = raw.trim();
    if (!line || line.startsWith(";")) continue;
    const [code, ...words] = line.split(/\s+/);
    const c = { code, x: NaN, y: NaN, z: NaN };
    for (const w of words) c[w[0].toLowerCase()] = Number(w.slice(1));
    out.push(c);
  }
  return out;
}

/** A binary STL of the box [0,a]×[0,b]×[0,c], outward facets, turned by `deg` about x;
 *  `dropFacet` leaves one facet out (an open mesh). */
export function boxStl(a, b, c, { deg = 0, dropFacet = -1 } = {}) {
  const t = (deg * Math.PI) / 180;
  const v = (x, y, z) => [x * a, y * b * Math.cos(t) - z * c * Math.sin(t), y * b * Math.sin(t) + z * c * Math.cos(t)];
  const quads = [
    [v(0, 0, 0), v(0, 1, 0), v(1, 1, 0), v(1, 0, 0)], // bottom, facing -z
    [v(0, 0, 1), v(1, 0, 1), v(1, 1, 1), v(0, 1, 1)], // top
    [v(0, 0, 0), v(1, 0, 0), v(1, 0, 1), v(0, 0, 1)], // front, -y
    [v(1, 0, 0), v(1, 1, 0), v(1, 1, 1), v(1, 0, 1)], // right, +x
    [v(1, 1, 0), v(0, 1, 0), v(0, 1, 1), v(1, 1, 1)], // back, +y
    [v(0, 1, 0), v(0, 0, 0), v(0, 0, 1), v(0, 1, 1)], // left, -x
  ];
  const tris = quads.flatMap(([p, q, r, s]) => [[p, q, r], [p, r, s]]).filter((_, i) => i !== dropFacet);
  const buf = Buffer.alloc(84 + 50 * tris.length);
  buf.writeUInt32LE(tris.length, 80);
  tris.forEach((tri, i) => tri.flat().forEach((x, k) => buf.writeFloatLE(x, 84 + 50 * i + 12 + 4 * k)));
  return buf;
}

/** A closed torus as a binary STL with 2·nu·nv facets (R, r in mm). */
export function torusStl(nu, nv, R = 40, r = 12) {
  const n = 2 * nu * nv;
  const buf = Buffer.alloc(84 + 50 * n);
  buf.write("dropslice test torus", 0, "ascii");
  buf.writeUInt32LE(n, 80);
  const P = (i, j) => {
    const u = (2 * Math.PI * (i % nu)) / nu;
    const v = (2 * Math.PI * (j % nv)) / nv;
    return [(R + r * Math.cos(v)) * Math.cos(u), (R + r * Math.cos(v)) * Math.sin(u), r * Math.sin(v)];
  };
  let o = 84;
  const tri = (a, b, c) => {
    o += 12; // normal left zero: readers compute it from the winding
    for (const p of [a, b, c]) for (const x of p) { buf.writeFloatLE(x, o); o += 4; }
    o += 2;
  };
  for (let i = 0; i < nu; i++) {
    for (let j = 0; j < nv; j++) {
      const a = P(i, j), b = P(i + 1, j), c = P(i + 1, j + 1), d = P(i, j + 1);
      tri(a, b, c);
      tri(a, c, d);
    }
  }
  return buf;
}

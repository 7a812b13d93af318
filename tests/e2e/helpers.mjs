// Shared helpers of the browser tests: a static server for dist/, Debian's Chromium through
// playwright-core, paths of the shared models, and a G-code parser for comparisons.
import { existsSync } from "node:fs";
import { dirname, join, resolve } from "node:path";
import { fileURLToPath } from "node:url";
import { chromium } from "playwright-core";
import { serve } from "../../scripts/serve.mjs";

export const repo = resolve(dirname(fileURLToPath(import.meta.url)), "../..");
export const shared = resolve(process.env.DROPSLICE_SHARED ?? join(repo, "../shared"));
export const benchy = join(shared, "models/3DBenchy.stl");
export const chromiumPath = process.env.CHROMIUM ?? "/usr/bin/chromium";

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

/** A new page that fails the test on page errors it did not expect. */
export async function openPage(browser, url, { width = 1440, height = 900, scale = 1 } = {}) {
  const context = await browser.newContext({ viewport: { width, height }, deviceScaleFactor: scale, acceptDownloads: true });
  const page = await context.newPage();
  const errors = [];
  page.on("pageerror", (e) => errors.push(String(e)));
  page.on("console", (m) => {
    if (m.type() === "error") errors.push(m.text());
  });
  await page.goto(url);
  return { page, context, errors };
}

export const status = (page) => page.evaluate(() => window.dropslice.status());

/** Waits until the page has finished a slice (or failed); returns its status. */
export async function waitSettled(page, timeout = 240_000) {
  await page.waitForFunction(
    () => ["done", "error", "cancelled"].includes(document.body.dataset.state ?? ""),
    null,
    { timeout, polling: 100 },
  );
  return status(page);
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

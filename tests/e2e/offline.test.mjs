// Offline use (www/pwa/sw.ts, www/pwa/offline.ts): the manifest is linked and parses; after a first
// visit the page loads and slices with the server gone and the browser offline, and gives the
// same G-code as online; a new build served on the same origin installs beside the old one,
// the page offers it, and Reload brings the new build with only its cache left.
// Each test serves its own copy of dist/ on its own port (its own origin: its own worker).
import { after, before, test } from "node:test";
import assert from "node:assert/strict";
import { cpSync, mkdtempSync, readFileSync, rmSync, writeFileSync } from "node:fs";
import { tmpdir } from "node:os";
import { join, resolve } from "node:path";
import { serve } from "../../scripts/serve.mjs";
import { downloadText, launchBrowser, open3d, openPage, pixels3d, repo, status, waitSettled } from "./helpers.mjs";

const dist = resolve(process.env.DROPSLICE_DIST ?? join(repo, "dist"));
const tmp = mkdtempSync(join(tmpdir(), "dropslice-offline-"));
let browser;
const servers = [];

before(async () => {
  browser = await launchBrowser();
});

after(async () => {
  await browser?.close().catch(() => {});
  for (const s of servers) {
    s.closeAllConnections();
    await new Promise((ok) => s.close(ok));
  }
  rmSync(tmp, { recursive: true, force: true });
});

/** A copy of dist/ served on a port of its own: { root, server, url }. */
async function servedCopy(name) {
  const root = join(tmp, name);
  cpSync(dist, root, { recursive: true });
  const { server, url } = await serve(root, 0);
  servers.push(server);
  return { root, server, url };
}

/** A fresh browser context on `url`, recording page and console errors. */
const visit = (url) => openPage(browser, url, { width: 1280, height: 800 });

/** Waits until a service worker controls the page; returns its cache names. */
async function controlled(page) {
  await page.waitForFunction(() => navigator.serviceWorker.controller !== null, null, { timeout: 30_000 });
  return page.evaluate(() => caches.keys());
}

async function sliced(page) {
  const s = await waitSettled(page, 120_000);
  const banner = await page.locator("#banner").innerText().catch(() => "");
  assert.equal(s.state, "done", `page state ${s.state}: ${banner}`);
  return s;
}

test("the manifest is linked, parses and names icons that load", async () => {
  const { url } = await servedCopy("manifest");
  const { page, context, errors } = await visit(url);
  const m = await page.evaluate(async () => {
    const link = document.querySelector('link[rel="manifest"]');
    const res = await fetch(link.href);
    const json = await res.json();
    const icons = [];
    for (const icon of json.icons) {
      const r = await fetch(new URL(icon.src, link.href));
      const blob = await r.blob();
      const entry = { ...icon, ok: r.ok, type_served: r.headers.get("content-type") };
      if (icon.type === "image/png") {
        const bitmap = await createImageBitmap(blob);
        Object.assign(entry, { width: bitmap.width, height: bitmap.height });
      } else entry.text = await blob.text();
      icons.push(entry);
    }
    return { type: res.headers.get("content-type"), json, icons };
  });
  assert.equal(m.type, "application/manifest+json");
  assert.equal(m.json.short_name, "dropslice");
  assert.equal(m.json.start_url, ".");
  assert.equal(m.json.display, "standalone");
  assert.match(m.json.theme_color, /^#[0-9a-f]{6}$/i);
  assert.match(m.json.background_color, /^#[0-9a-f]{6}$/i);
  for (const size of [192, 512]) {
    const icon = m.icons.find((i) => i.sizes === `${size}x${size}`);
    assert.ok(icon, `a ${size} px icon: ${JSON.stringify(m.icons)}`);
    assert.equal(icon.type_served, "image/png");
    assert.deepEqual([icon.width, icon.height], [size, size]);
  }
  const svg = m.icons.find((i) => i.type === "image/svg+xml");
  assert.ok(svg && svg.ok && svg.type_served === "image/svg+xml", JSON.stringify(m.icons));
  assert.match(svg.text, /^<svg xmlns="http:\/\/www.w3.org\/2000\/svg"[^>]*viewBox=/);
  await sliced(page);
  assert.deepEqual(errors, []);
  await context.close();
});

test("after the first visit the page loads and slices offline, with the same G-code", async () => {
  const { server, url } = await servedCopy("offline");
  const { page, context, errors } = await visit(url);
  const caches = await controlled(page);
  assert.equal(caches.length, 1);
  assert.match(caches[0], /^dropslice-shell-[0-9a-f]{16}$/);
  const online = await sliced(page);
  const gcodeOnline = await downloadText(page);

  // no network at all: the server is gone and the browser is offline
  server.closeAllConnections();
  await new Promise((ok) => server.close(ok));
  await context.setOffline(true);
  await assert.rejects(fetch(url), "the server is gone");
  await page.reload();
  const s = await sliced(page);
  assert.equal(s.name, "sample-block-with-boss.stl");
  assert.equal(s.layers, online.layers);
  assert.deepEqual(s.counts, online.counts);
  assert.ok(await page.evaluate(() => navigator.serviceWorker.controller !== null));
  const gcodeOffline = await downloadText(page);
  assert.ok(gcodeOffline.split("\n").filter((l) => /^G2[56]\b/.test(l)).length > 1000, "droplet commands");
  assert.equal(gcodeOffline, gcodeOnline);
  // the 3D view's code (a chunk the page loads only now, when the tab is first opened) comes
  // from the cache too, and draws the part
  const view = await open3d(page);
  assert.deepEqual(view.parts, ["0:0"]);
  const px = await pixels3d(page);
  assert.ok(px.part.n > 1000, `part pixels in 3D: ${px.part.n}`);
  assert.deepEqual(errors, []);
  await context.close();
});

test("a new build is installed beside the old one, offered, and taken on Reload", async () => {
  const { root, url } = await servedCopy("update");
  const { page, context, errors } = await visit(url);
  const [first] = await controlled(page);
  await sliced(page);
  const oldId = first.replace("dropslice-shell-", "");
  const swFile = join(root, "sw.js");
  const sw = readFileSync(swFile, "utf8");
  assert.ok(sw.includes(oldId), "sw.js names its build");
  assert.equal(await page.isVisible("#update-note"), false);

  // a new build on the same origin: another index.html, and a sw.js with another build id
  const newId = [...oldId].reverse().join("") === oldId ? "0".repeat(16) : [...oldId].reverse().join("");
  const html = readFileSync(join(root, "index.html"), "utf8");
  writeFileSync(join(root, "index.html"), html.replace("<head>", '<head>\n  <meta name="dropslice-build" content="second">'));
  writeFileSync(swFile, sw.split(oldId).join(newId));

  // the page asks (as it does hourly; a navigation would too)
  await page.evaluate(() => navigator.serviceWorker.getRegistration().then((r) => r.update()));
  await page.waitForSelector("#update-note", { state: "visible", timeout: 30_000 });
  assert.match(await page.locator("#update-note").innerText(), /A new version is ready/);
  // until Reload, the old build still serves this page and both caches exist
  assert.deepEqual((await page.evaluate(() => caches.keys())).sort(), [`dropslice-shell-${newId}`, first].sort());
  assert.equal(await page.evaluate(() => document.querySelector('meta[name="dropslice-build"]')), null);

  const reloaded = page.waitForEvent("load");
  await page.click("#btn-update");
  await reloaded;
  await page.waitForFunction(() => document.querySelector('meta[name="dropslice-build"]') !== null, null, { timeout: 30_000 });
  await controlled(page);
  assert.deepEqual(await page.evaluate(() => caches.keys()), [`dropslice-shell-${newId}`]);
  assert.equal(await page.isVisible("#update-note"), false);
  await sliced(page);
  assert.ok((await status(page)).droplets > 0);
  assert.deepEqual(errors, []);
  await context.close();
});

// The core's module is compiled once by the page and posted to every worker
// (core/client.ts `compiledCore`): no worker fetches, compiles or instantiates it from bytes.
// The page's only request for it is the page's own; on a second load it is answered by the
// cache (the service worker's, or a 304 of the server).
import { test } from "node:test";
import assert from "node:assert/strict";
import { readFileSync } from "node:fs";
import { join } from "node:path";
import { benchy, openPage, pick, repo, startForTests, waitDone, waitSettled } from "./helpers.mjs";

const env = startForTests();

/** Counts, inside a worker, every way of getting a module other than the posted one: a fetch of
 *  a .wasm, compile/compileStreaming, instantiate of bytes, instantiateStreaming, `new
 *  WebAssembly.Module`. Put before the worker's bundle (one file, no imports). */
const PRELUDE = `(() => {
  const use = (globalThis.__wasmUse = { fetch: 0, compile: 0, instantiateBytes: 0, streaming: 0, newModule: 0, instances: 0 });
  const W = WebAssembly;
  const f = globalThis.fetch;
  globalThis.fetch = function (r, ...rest) {
    if (/\\.wasm(\\?|$)/.test(String(r?.url ?? r))) use.fetch++;
    return f.call(this, r, ...rest);
  };
  const compile = W.compile;
  W.compile = function (...a) { use.compile++; return compile.apply(this, a); };
  const cs = W.compileStreaming;
  W.compileStreaming = function (...a) { use.streaming++; return cs.apply(this, a); };
  const is = W.instantiateStreaming;
  W.instantiateStreaming = function (...a) { use.streaming++; return is.apply(this, a); };
  const inst = W.instantiate;
  W.instantiate = function (m, ...a) { if (!(m instanceof W.Module)) use.instantiateBytes++; return inst.call(this, m, ...a); };
  W.Module = new Proxy(W.Module, { construct(t, a, n) { use.newModule++; return Reflect.construct(t, a, n); } });
  W.Instance = new Proxy(W.Instance, { construct(t, a, n) { use.instances++; return Reflect.construct(t, a, n); } });
})();
`;

test("the worker's bundle holds no way to fetch the module", () => {
  const worker = readFileSync(join(process.env.DROPSLICE_DIST ?? join(repo, "dist"), "worker.js"), "utf8");
  assert.doesNotMatch(worker, /dropslice_bg\.wasm/);
  assert.doesNotMatch(worker, /compileStreaming|instantiateStreaming/);
});

test("one request for the module per page, none from the workers; every worker instantiates the page's module; the slice is complete", async () => {
  const context = await env.browser.newContext();
  // the service worker precaches the module itself: its requests are counted apart
  const requests = [];
  context.on("request", (r) => {
    if (/dropslice_bg\.wasm/.test(r.url())) requests.push({ fromSw: r.serviceWorker() !== null });
  });
  await context.route(/\/worker\.js$/, async (route) => {
    const response = await route.fetch();
    route.fulfill({ response, body: PRELUDE + (await response.text()) });
  });
  const page = await context.newPage();
  const errors = [];
  page.on("pageerror", (e) => errors.push(String(e)));
  page.on("console", (m) => {
    if (m.type() === "error") errors.push(m.text());
  });
  await page.goto(env.url);
  await waitSettled(page, 60_000);
  await pick(page, benchy);
  const s = await waitDone(page);
  assert.ok(s.layers > 200, JSON.stringify(s));
  const workers = page.workers().filter((w) => /worker\.js/.test(w.url()));
  assert.ok(workers.length >= 2, `${workers.length} workers`);
  for (const w of workers) {
    const use = await w.evaluate(() => globalThis.__wasmUse);
    assert.deepEqual(use, { fetch: 0, compile: 0, instantiateBytes: 0, streaming: 0, newModule: 0, instances: 1 }, w.url());
  }
  const fromPage = requests.filter((r) => !r.fromSw);
  assert.equal(fromPage.length, 1, JSON.stringify(requests));
  const entries = await page.evaluate(() => performance.getEntriesByName("dropslice: compile").length);
  assert.equal(entries, 1, "the page compiled the module once");
  assert.deepEqual(errors, []);
  await context.close();
});

test("the page compiles the module once: a cancel's fresh workers get the same module", async () => {
  const { page, context, errors } = await openPage(env.browser, env.url);
  const requests = [];
  page.on("request", (r) => {
    if (/dropslice_bg\.wasm/.test(r.url()) && r.serviceWorker() === null) requests.push(r.url());
  });
  await waitSettled(page, 60_000);
  const before = requests.length;
  // a cancel terminates every worker and starts fresh ones
  await pick(page, benchy);
  await page.waitForFunction(() => document.body.dataset.state === "slicing", null, { timeout: 60_000, polling: 10 });
  await page.click("#btn-cancel");
  await waitSettled(page, 60_000);
  assert.equal((await page.evaluate(() => document.body.dataset.state)), "cancelled");
  await pick(page, benchy);
  await waitDone(page);
  assert.equal(requests.length, before, "no new request for the module after the cancel");
  assert.equal(await page.evaluate(() => performance.getEntriesByName("dropslice: compile").length), 1);
  assert.deepEqual(errors, []);
  await context.close();
});

test("a server that sends the module with another type: the page compiles its bytes and slices", async () => {
  const context = await env.browser.newContext();
  const page = await context.newPage();
  const errors = [];
  page.on("pageerror", (e) => errors.push(String(e)));
  let served = 0;
  await context.route(/dropslice_bg\.wasm$/, async (route) => {
    const response = await route.fetch();
    if (!route.request().serviceWorker()) served++;
    route.fulfill({ response, headers: { ...response.headers(), "content-type": "application/octet-stream" } });
  });
  await page.goto(env.url);
  const s = await waitSettled(page, 120_000);
  assert.equal(s.state, "done", await page.locator("#banner").innerText().catch(() => JSON.stringify(s)));
  assert.equal(served, 1);
  assert.deepEqual(errors, []);
  await context.close();
});

// scripts/serve.mjs serves only files inside its root: traversal in every spelling, a sibling
// folder whose name starts like the root's, symbolic links pointing out, NUL bytes and
// malformed percent-encoding are refused (404 or 400, never 500 and never the file).
import { after, before, test } from "node:test";
import assert from "node:assert/strict";
import { request } from "node:http";
import { mkdirSync, mkdtempSync, rmSync, symlinkSync, writeFileSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { serve } from "../../scripts/serve.mjs";

const tmp = mkdtempSync(join(tmpdir(), "dropslice-serve-"));
const root = join(tmp, "dist");
let server;
let port;

before(async () => {
  mkdirSync(join(root, "sub"), { recursive: true });
  writeFileSync(join(root, "index.html"), "<!doctype html><title>root</title>");
  writeFileSync(join(root, "app.js"), "export {};");
  writeFileSync(join(root, "sub", "index.html"), "sub");
  mkdirSync(join(tmp, "dist-secret"));
  writeFileSync(join(tmp, "dist-secret", "key.txt"), "SECRET");
  writeFileSync(join(tmp, "outside.txt"), "SECRET");
  symlinkSync(join(tmp, "outside.txt"), join(root, "link.txt"));
  symlinkSync(join(tmp, "dist-secret"), join(root, "linkdir"));
  symlinkSync(join(root, "app.js"), join(root, "inner.js")); // a link that stays inside
  ({ server } = await serve(root, 0));
  port = server.address().port;
});

after(async () => {
  await new Promise((ok) => server?.close(ok));
  rmSync(tmp, { recursive: true, force: true });
});

/** GET with the path sent exactly as written (no client-side normalisation). */
function get(path) {
  return new Promise((ok, fail) => {
    const req = request({ host: "127.0.0.1", port, path, method: "GET" }, (res) => {
      let body = "";
      res.setEncoding("utf8");
      res.on("data", (c) => (body += c));
      res.on("end", () => ok({ status: res.statusCode, body, type: res.headers["content-type"], csp: res.headers["content-security-policy"] }));
    });
    req.on("error", fail);
    req.end();
  });
}

test("files inside the root are served", async () => {
  for (const [path, body] of [["/", "<!doctype html><title>root</title>"], ["/index.html", null], ["/app.js", "export {};"], ["/sub/", "sub"], ["/sub", "sub"], ["/inner.js", "export {};"], ["/./app.js", "export {};"], ["/sub/../app.js", "export {};"]]) {
    const r = await get(path);
    assert.equal(r.status, 200, path);
    if (body !== null) assert.equal(r.body, body, path);
  }
  const js = await get("/app.js");
  assert.match(js.type, /javascript/);
  assert.match(js.csp, /script-src 'self' 'wasm-unsafe-eval'/);
  assert.match(js.csp, /frame-ancestors 'none'/);
});

test("traversal, links out, NUL and bad encoding are refused", async () => {
  const cases = [
    ["/..%2fdist-secret/key.txt", 404],
    ["/..%2Fdist-secret%2Fkey.txt", 404],
    ["/../dist-secret/key.txt", 404],
    ["/%2e%2e/dist-secret/key.txt", 404],
    ["/%2E%2E%2Fdist-secret%2Fkey.txt", 404],
    ["/.%2e/dist-secret/key.txt", 404],
    ["/..%5cdist-secret%5ckey.txt", 404],
    ["/..\\dist-secret\\key.txt", 404],
    ["/%5c..%5c..%5cdist-secret%5ckey.txt", 404],
    ["/..%2f..%2f..%2f..%2f..%2f..%2fetc%2fpasswd", 404],
    ["/..%2foutside.txt", 404],
    ["/link.txt", 404],
    ["/linkdir/key.txt", 404],
    ["/linkdir/", 404],
    ["/missing.txt", 404],
    ["/app.js%00.html", 400],
    ["/%00", 400],
    ["/%E0%A4%A", 400],
    ["/%", 400],
    ["/%zz", 400],
  ];
  for (const [path, status] of cases) {
    const r = await get(path);
    assert.equal(r.status, status, `${path}: ${r.status} ${r.body}`);
    assert.doesNotMatch(r.body, /SECRET/, path);
  }
});

/** GET with request headers; the status and the headers of the answer. */
function getWith(path, headers) {
  return new Promise((ok, fail) => {
    const req = request({ host: "127.0.0.1", port, path, method: "GET", headers }, (res) => {
      let body = "";
      res.setEncoding("utf8");
      res.on("data", (c) => (body += c));
      res.on("end", () => ok({ status: res.statusCode, body, headers: res.headers }));
    });
    req.on("error", fail);
    req.end();
  });
}

test("files carry validators; a request naming the current one gets a 304 without the body", async () => {
  const first = await getWith("/app.js", {});
  assert.equal(first.status, 200);
  assert.equal(first.headers["cache-control"], "no-cache");
  const tag = first.headers.etag;
  const modified = first.headers["last-modified"];
  assert.match(tag, /^"[0-9a-f]+-[0-9a-f]+"$/);
  assert.ok(Number.isFinite(Date.parse(modified)), modified);

  const again = await getWith("/app.js", { "if-none-match": tag });
  assert.equal(again.status, 304);
  assert.equal(again.body, "");
  assert.equal(again.headers.etag, tag);
  assert.equal((await getWith("/app.js", { "if-none-match": `"other", W/${tag}` })).status, 304);
  assert.equal((await getWith("/app.js", { "if-modified-since": modified })).status, 304);
  // another tag: the file; If-None-Match wins over a date that would match
  const other = await getWith("/app.js", { "if-none-match": '"0-0"', "if-modified-since": modified });
  assert.equal(other.status, 200);
  assert.equal(other.body, "export {};");
  assert.equal((await getWith("/app.js", { "if-modified-since": "not a date" })).status, 200);
  assert.equal((await getWith("/app.js", { "if-modified-since": new Date(Date.parse(modified) - 5000).toUTCString() })).status, 200);

  // a changed file gets a new tag and is sent again to the old one
  await new Promise((r) => setTimeout(r, 20));
  writeFileSync(join(root, "app.js"), "export {}; // changed");
  const changed = await getWith("/app.js", { "if-none-match": tag });
  assert.equal(changed.status, 200);
  assert.equal(changed.body, "export {}; // changed");
  assert.notEqual(changed.headers.etag, tag);
  writeFileSync(join(root, "app.js"), "export {};");
  // a refused path never gets a 304
  assert.equal((await getWith("/link.txt", { "if-none-match": "*" })).status, 404);
});

// A tiny static file server for dist/ (correct MIME types, application/wasm included), with
// validators: every file has an ETag (its size and modification time) and a Last-Modified, and
// a request that names the current one (If-None-Match, else If-Modified-Since) gets a 304
// without the body. The browser's HTTP cache keeps the module's response, so a second visit
// compiles it from V8's code cache (docs/performance.md "The module, compiled once").
// Usage: node scripts/serve.mjs [port]   (default 8080, or $PORT); 0 picks a free port.
import { createServer } from "node:http";
import { readFile, realpath, stat } from "node:fs/promises";
import { extname, join, resolve, sep } from "node:path";
import { fileURLToPath } from "node:url";

const TYPES = {
  ".html": "text/html; charset=utf-8",
  ".js": "text/javascript; charset=utf-8",
  ".mjs": "text/javascript; charset=utf-8",
  ".css": "text/css; charset=utf-8",
  ".wasm": "application/wasm",
  ".map": "application/json",
  ".json": "application/json",
  ".webmanifest": "application/manifest+json",
  ".svg": "image/svg+xml",
  ".png": "image/png",
  ".stl": "model/stl",
};

/** A request the server refuses, with its status. */
class Refused extends Error {
  constructor(status) {
    super(status === 400 ? "bad request" : "not found");
    this.status = status;
  }
}

/**
 * The file a URL path names inside `root` (a real path, links resolved), or a Refused:
 * 400 for malformed percent-encoding or a NUL byte, 404 for anything that is missing or whose
 * real path is not `root` itself or inside `root` + separator (`..`, encoded or not, a sibling
 * folder whose name starts like root's, a symbolic link pointing out).
 */
async function locate(root, url) {
  let path;
  try {
    path = decodeURIComponent(new URL(url ?? "/", "http://x").pathname);
  } catch {
    throw new Refused(400);
  }
  if (path.includes("\0")) throw new Refused(400);
  const inside = (p) => p === root || p.startsWith(root + sep);
  const real = async (p) => {
    try {
      return await realpath(p);
    } catch {
      throw new Refused(404);
    }
  };
  let file = await real(join(root, path));
  if (!inside(file)) throw new Refused(404);
  if ((await stat(file)).isDirectory()) {
    file = await real(join(file, "index.html"));
    if (!inside(file) || (await stat(file)).isDirectory()) throw new Refused(404);
  }
  return file;
}

/** The policy of www/index.html, plus what only a header can say (frame-ancestors). */
const CSP =
  "default-src 'self'; script-src 'self' 'wasm-unsafe-eval'; worker-src 'self'; connect-src 'self'; manifest-src 'self'; " +
  "img-src 'self' data: blob:; style-src 'self'; object-src 'none'; base-uri 'none'; form-action 'none'; " +
  "frame-ancestors 'none'";

/** A strong validator of a file (its `stat` with bigint numbers): its size and modification
 *  time in ns, quoted. */
function etagOf(info) {
  return `"${info.size.toString(16)}-${info.mtimeNs.toString(16)}"`;
}

/** Whether the request's validators name the file as it is (RFC 9110 13.1: If-None-Match
 *  wins over If-Modified-Since; a date that does not parse is ignored). */
function unchanged(headers, tag, modified) {
  const match = headers["if-none-match"];
  if (match !== undefined) {
    if (match.trim() === "*") return true;
    return match.split(",").some((t) => t.trim().replace(/^W\//, "") === tag);
  }
  const since = headers["if-modified-since"];
  if (since === undefined) return false;
  const at = Date.parse(since);
  return Number.isFinite(at) && modified.getTime() <= at;
}

/** Serves `root` on 127.0.0.1:`port`; resolves to { server, url }. */
export function serve(root, port = 0) {
  let base = null; // root's real path, resolved at the first request
  const server = createServer(async (req, res) => {
    try {
      base ??= await realpath(resolve(root));
      const file = await locate(base, req.url);
      const info = await stat(file, { bigint: true });
      const tag = etagOf(info);
      const modified = new Date(Number(info.mtimeMs / 1000n) * 1000);
      const headers = {
        "content-type": TYPES[extname(file)] ?? "application/octet-stream",
        // no-cache: the browser asks again every time (a 304 when nothing changed), which is
        // also what lets it find a new service worker (sw.js) as soon as a new build is served
        "cache-control": "no-cache",
        etag: tag,
        "last-modified": modified.toUTCString(),
        // The page's policy (as in index.html's meta tag) also as a header, which covers the
        // workers' scripts and framing too; nosniff keeps types as served.
        "content-security-policy": CSP,
        "x-content-type-options": "nosniff",
      };
      if (unchanged(req.headers, tag, modified)) {
        res.writeHead(304, headers);
        res.end();
        return;
      }
      const body = await readFile(file);
      res.writeHead(200, headers);
      res.end(body);
    } catch (e) {
      const status = e instanceof Refused ? e.status : e?.code === "ENOENT" || e?.code === "ENOTDIR" ? 404 : 500;
      res.writeHead(status, { "content-type": "text/plain" });
      res.end(status === 400 ? "bad request" : status === 404 ? "not found" : "server error");
    }
  });
  return new Promise((ok, fail) => {
    server.once("error", fail);
    server.listen(port, "127.0.0.1", () => {
      const { port: p } = server.address();
      ok({ server, url: `http://127.0.0.1:${p}/` });
    });
  });
}

if (process.argv[1] && resolve(process.argv[1]) === fileURLToPath(import.meta.url)) {
  const root = resolve(fileURLToPath(import.meta.url), "../../dist");
  const port = Number(process.argv[2] ?? process.env.PORT ?? 8080);
  const { url } = await serve(root, port);
  console.log(`dropslice is running at ${url}  (Ctrl+C to stop)`);
}

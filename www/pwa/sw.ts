// The service worker (dist/sw.js): the page works without network after the first visit.
//
// * The app shell (SHELL: every built file, the chunks the page loads on demand too) is
//   precached on install, as one unit, in a cache named after the build (BUILD_ID: a hash of
//   the built files; both injected by scripts/build.sh), and served cache-first. Old builds' caches are deleted on activate.
// * Navigations to the page are served cache-first too, from the same build's cache. Not
//   network-first: a fresh index.html from the network would run with the old build's
//   main.js, worker.js and wasm from the cache, two builds mixed. Updates are still seen when
//   online: the browser checks sw.js (served with no-cache) on every navigation (and the page
//   asks again hourly); a new build's sw.js differs (its BUILD_ID), installs beside the old one
//   and precaches the new shell, then waits. The page (offline.ts) shows "A new version is
//   ready" and, when the user presses Reload, tells the waiting worker to take over; the page
//   reloads under the new build. Until then every request of the open page (its workers'
//   wasm included) is served from the old build's cache, so nothing mixes.
// * Only same-origin GET requests are answered; anything else (other origins, POST, files the
//   shell does not list, such as source maps) goes to the network untouched, and nothing is
//   cached at run time.

export {};

declare const BUILD_ID: string;
/** The page's files, relative to the worker's scope (the folder of sw.js): every file of the
 *  build but source maps and sw.js itself, the 3D view's chunks included (listed by
 *  scripts/build.sh, which injects the list: chunk names carry a hash of their content). */
declare const SHELL: readonly string[];

const sw = self as unknown as ServiceWorkerGlobalScope;

const PREFIX = "dropslice-shell-";
const CACHE = PREFIX + BUILD_ID;

const scope = () => new URL(sw.registration.scope);

sw.addEventListener("install", (ev) => {
  ev.waitUntil(
    (async () => {
      const cache = await caches.open(CACHE);
      // cache: "reload": from the server, never from the HTTP cache (another build's file)
      await cache.addAll(SHELL.map((f) => new Request(new URL(f, scope()), { cache: "reload" })));
    })(),
  );
});

sw.addEventListener("activate", (ev) => {
  ev.waitUntil(
    (async () => {
      for (const name of await caches.keys()) {
        if (name.startsWith(PREFIX) && name !== CACHE) await caches.delete(name);
      }
      // the first visit's page is controlled at once (it came from the network, the same build)
      await sw.clients.claim();
    })(),
  );
});

sw.addEventListener("message", (ev) => {
  if ((ev.data as { type?: unknown } | null)?.type === "skip-waiting") void sw.skipWaiting();
});

/** Whether a navigation is to the page itself (the scope's folder or its index.html; any
 *  query or fragment: the page reads them). */
function isPage(url: URL): boolean {
  const base = scope().pathname;
  return url.pathname === base || url.pathname === base + "index.html";
}

async function fromCache(key: Request | string, request: Request): Promise<Response> {
  const cache = await caches.open(CACHE);
  const hit = await cache.match(key);
  return hit ?? fetch(request);
}

sw.addEventListener("fetch", (ev) => {
  const req = ev.request;
  if (req.method !== "GET") return;
  const url = new URL(req.url);
  if (url.origin !== sw.location.origin) return;
  if (req.mode === "navigate") {
    if (isPage(url)) ev.respondWith(fromCache(new URL("index.html", scope()).href, req));
    return;
  }
  // the shell's files, exactly (a query string makes another file: it goes to the network)
  ev.respondWith(fromCache(req, req));
});

// Offline use: registers the service worker (sw.ts, dist/sw.js) and offers a new build when
// one is ready. Only on secure contexts (https, and http://127.0.0.1 or localhost), where
// browsers allow service workers. See sw.ts for what is cached and when it updates.

import { $ } from "../views/dom";

/** How often an open page asks whether a new build is served (browsers also check on every
 *  navigation). */
const UPDATE_CHECK_MS = 60 * 60 * 1000;

export function registerOffline(): void {
  if (!window.isSecureContext || !("serviceWorker" in navigator)) return;
  navigator.serviceWorker.register("sw.js", { scope: "./" }).then(watch, (e: unknown) => {
    // the page works as before, only not offline
    console.warn(`dropslice: offline use is not available (${e instanceof Error ? e.message : String(e)})`);
  });
}

function watch(reg: ServiceWorkerRegistration): void {
  const sw = navigator.serviceWorker;
  let asked = false;
  // a new build waiting while an older one controls this page: offer it
  const offer = (next: ServiceWorker) => {
    const note = $("update-note");
    note.hidden = false;
    $("btn-update").onclick = () => {
      asked = true;
      next.postMessage({ type: "skip-waiting" });
    };
  };
  if (reg.waiting && sw.controller) offer(reg.waiting);
  reg.addEventListener("updatefound", () => {
    const next = reg.installing;
    next?.addEventListener("statechange", () => {
      if (next.state === "installed" && sw.controller) offer(next);
    });
  });
  // the new build took over (after Reload was pressed): load the page from it. Not on the
  // first visit, when the first worker claims the page.
  sw.addEventListener("controllerchange", () => {
    if (asked) location.reload();
  });
  setInterval(() => reg.update().catch(() => {}), UPDATE_CHECK_MS);
}

// An error shown in the page; after a crash the new workers get the finished slice's model back.

import { SliceError } from "../core/client";
import type { Page } from "../views/page";
import { errorBanner } from "../views/banner";
import { setState } from "../views/status";

/** After the workers were replaced (cancel, crash), lets them hold the finished slice's model
 *  again, so its evicted layers and its download keep working. */
export function restoreModel(page: Page): void {
  const { store, pool } = page;
  const s = store.slice;
  if (!s || !s.complete || s.source !== "stl" || !s.job || store.busy) return;
  pool.open(s.job.refs, s.job.file).catch(() => {
    // the slice stays visible; what needs a worker reports its own error
  });
}

export function showError(page: Page, e: unknown): void {
  if (e instanceof SliceError && e.kind === "crash") restoreModel(page);
  errorBanner(e);
  setState("error");
}

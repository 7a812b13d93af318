// The share dialog: makes the preview link of the slice shown, copies it, and shows it.

import { nonDefault } from "../core/settings";
import type { Page } from "./page";
import { fullSpec, jobSettings, specOut } from "../core/job";
import { makeLink } from "../core/share";
import { sliceState } from "./controls";
import { $ } from "./dom";

export async function share(page: Page): Promise<void> {
  const { store, renderer } = page;
  const s = store.slice;
  const job = s?.job;
  // only the slice of the job as it is now (the button says so when it is not)
  if (!s || !job || s.source !== "stl" || job.refs.length === 0 || sliceState(page) !== "current") return;
  const camera = page.view3d.active ? page.view3d.camera() : null;
  const cut = page.actions.cutLine();
  // the job as it was sliced: its files (embedded in this order when they fit) and parts
  const files = job.refs.map((r, i) => ({ name: r.name, sha256: job.sha256[i], bytes: r.file.size }));
  const { url, embedded } = await makeLink(location.href, {
    // the settings that differ from the defaults (the link carries only those)
    settings: nonDefault(jobSettings(s.settings)),
    layer: store.current,
    view: { ...renderer.view },
    name: files[0].name,
    sha256: files[0].sha256,
    showTravel: renderer.showTravel,
    mode: page.view3d.active ? "3d" : "layer",
    ...(camera ? { camera } : {}),
    ...(cut ? { cut } : {}),
    overlays: { below: renderer.showBelow, voids: renderer.showVoids, overhangs: renderer.showOverhangs },
    files,
    parts: job.file.parts.map((p) => specOut(fullSpec(p))),
  }, job.refs.map((r) => r.file));
  const several = files.length > 1;
  let copied = false;
  try {
    // some browsers never settle the promise when they do not grant the permission
    copied = await Promise.race([
      navigator.clipboard.writeText(url).then(() => true),
      new Promise<boolean>((ok) => setTimeout(() => ok(false), 1500)),
    ]);
  } catch {
    // clipboard refused (permissions, insecure context): the dialog shows the link to copy
  }
  $("share-text").textContent =
    (copied ? "Copied to the clipboard. " : "Copy this link. ") +
    (embedded
      ? `The ${several ? "models are" : "model is"} inside the link (${Math.round(url.length / 1024)} KB), so it opens the same slice anywhere.`
      : several
        ? `The models are too big to embed, so the link carries their SHA-256: whoever opens it drops in the same files and the page checks that they match.`
        : `“${files[0].name}” is too big to embed, so the link carries its SHA-256: whoever opens it drops in the same file and the page checks that it matches.`);
  const input = $<HTMLInputElement>("share-url");
  input.value = url;
  $<HTMLDialogElement>("share-dialog").showModal();
  input.select();
}

// The user's work is safe in the page (www/flows/history.ts, flows/remember.ts, core/plate.ts,
// views/controls.ts, views/calibrate.ts, core/share.ts): what is downloaded is the job on screen,
// a refused job does not hand out the previous code, undo and redo by keys and buttons, Delete,
// the sample over a job undone, settings remembered over a reload (and reset), a link made in
// 3D opening in 3D with its camera, a part off the plate never sliced or downloaded, and the
// calibration bound to the code its mass was measured on. All through the DOM, as a user.
import { after, before, test } from "node:test";
import assert from "node:assert/strict";
import { readFileSync } from "node:fs";
import { deflateRawSync, inflateRawSync } from "node:zlib";
import { join } from "node:path";
import { boxStl, open3d, openPage, pick, shared, shareLink, startWithPage, status, stop, view3dReady, waitDone, waitSettled } from "./helpers.mjs";

let env;
let main;
const cube = { name: "cube_20mm_ascii.stl", mimeType: "model/stl", buffer: readFileSync(join(shared, "models/cube_20mm_ascii.stl")) };

before(async () => ({ env, main } = await startWithPage({ settle: true })));
after(() => stop(env));

const job = (page) => page.evaluate(() => window.dropslice.job());
const history = (page) => page.evaluate(() => window.dropslice.history());
const disabled = (page, id) => page.locator(`#${id}`).isDisabled();
/** A box STL to open as a file of the page. */
const box = (name, a, b, c) => ({ name, mimeType: "model/stl", buffer: boxStl(a, b, c) });

/** Presses `combo` with no field focused (the page's keys do not act while typing). */
async function key(page, combo) {
  await page.evaluate(() => document.activeElement instanceof HTMLElement && document.activeElement.blur());
  await page.keyboard.press(combo);
}

/** Clicks `selector` (Slice, Sample part) and waits for the slice it starts. */
async function clickSliced(page, selector) {
  await page.evaluate(() => (document.body.dataset.state = "picking"));
  await page.click(selector);
  return waitDone(page);
}

/** Clicks `selector` (an Undo) and waits until the job has the parts `parts` again. */
async function undoneTo(page, selector, parts) {
  await page.click(selector);
  await page.waitForFunction((n) => window.dropslice.job().parts.length === n, parts.length);
  assert.deepEqual((await job(page)).parts, parts);
}

/** Opens `files` as a new job and waits for its slice. */
async function openJob(page, files) {
  await pick(page, files);
  return waitDone(page);
}

test("four models that do not fit: no code of the previous job can be downloaded; Ctrl+Z brings it back", async () => {
  const { page, errors } = main;
  const before = await job(page);
  assert.match(before.name, /sample/);
  assert.equal(await disabled(page, "btn-download"), false, "the sample's slice is current");
  await pick(page, [box("big-a.stl", 100, 90, 10), box("big-b.stl", 100, 90, 10), box("big-c.stl", 100, 90, 10), box("big-d.stl", 100, 90, 10)]);
  const s = await waitSettled(page);
  assert.equal(s.state, "error");
  assert.match(await page.locator("#banner").innerText(), /fit/);
  assert.equal((await job(page)).name, "big-a.stl + 3 more", "the new parts are the job");
  // the slice went with the job it was of: nothing to download, link or show as current
  assert.equal(s.name, null, "no slice");
  assert.equal(await disabled(page, "btn-download"), true);
  assert.equal(await disabled(page, "btn-share"), true);
  assert.equal(await disabled(page, "btn-slice"), true, "a job that does not fit is not sliced");
  assert.equal(await page.locator("#stat-model").innerText(), "–");
  assert.match(await page.locator("#settings-status").innerText(), /do not fit/);
  // the new job replaced the sample: one Undo away, said so
  assert.match(await page.locator("#undo-note").innerText(), /replaced the previous job/);
  await key(page, "Control+z");
  await page.waitForFunction(() => /sample/.test(window.dropslice.job().name));
  // the same parts (their display meshes aside: the 3D view shown meanwhile fetched one)
  const specs = (parts) => parts.map(({ mesh, ...spec }) => spec);
  assert.deepEqual(specs((await job(page)).parts), specs(before.parts));
  assert.equal(await disabled(page, "btn-download"), true, "its slice was dropped: slice again first");
  assert.equal(await disabled(page, "btn-slice"), false);
  assert.deepEqual(errors, []);
});

test("Delete removes the selected part, Ctrl+Z brings it back (and the slice is current again), Ctrl+Y redoes", async () => {
  const { page, errors } = main;
  await openJob(page, [cube, box("slab.stl", 30, 20, 4)]);
  const sliced = await job(page);
  assert.equal(sliced.parts.length, 2);
  assert.equal(await page.getAttribute("body", "data-slice"), "ok");
  // typing in a field: Delete edits the field, not the job
  await page.click(".part-item:nth-child(2)");
  await page.focus("#part-place_x");
  await page.keyboard.press("Delete");
  assert.equal((await job(page)).parts.length, 2, "Delete in a field removes no part");
  // Delete on the selected part in the list
  await page.focus(".part-item:nth-child(2)");
  await page.keyboard.press("Delete");
  await page.waitForFunction(() => window.dropslice.job().parts.length === 1);
  assert.match((await history(page)).undo, /remove slab\.stl/);
  assert.match(await page.getAttribute("#btn-undo", "title"), /Undo remove slab\.stl/);
  // the slice is of two parts: out of date, marked so, not downloadable
  assert.equal(await page.getAttribute("body", "data-slice"), "stale");
  assert.equal(await page.isVisible("#stale-note"), true);
  assert.equal(await page.getAttribute("#stats-panel", "data-stale"), "");
  assert.equal(await disabled(page, "btn-download"), true);
  assert.match(await page.getAttribute("#btn-download", "title"), /out of date/);
  // Ctrl+Z: the part is back, the same part (id and spec), and the slice is current again
  await key(page, "Control+z");
  await page.waitForFunction(() => window.dropslice.job().parts.length === 2);
  assert.deepEqual((await job(page)).parts, sliced.parts);
  assert.equal(await page.getAttribute("body", "data-slice"), "ok");
  assert.equal(await disabled(page, "btn-download"), false);
  // redo (Ctrl+Y), then undo again with the button
  assert.equal(await disabled(page, "btn-redo"), false);
  await key(page, "Control+y");
  await page.waitForFunction(() => window.dropslice.job().parts.length === 1);
  await undoneTo(page, "#btn-undo", sliced.parts);
  assert.deepEqual(errors, []);
});

test("Sample part over a job replaces it with a notice whose Undo brings the job back", async () => {
  const { page, errors } = main;
  const before = await job(page);
  assert.equal(before.parts.length, 2);
  await clickSliced(page, "#btn-sample");
  assert.match((await job(page)).name, /sample/);
  assert.equal(await page.isVisible("#undo-note"), true);
  assert.match(await page.locator("#undo-text").innerText(), /replaced the previous job/);
  await undoneTo(page, "#undo-again", before.parts);
  assert.deepEqual(errors, []);
});

test("a part moved off the plate is drawn in the warning colour, named in plain words, never sliced or downloaded", async () => {
  const { page, errors } = main;
  await clickSliced(page, "#btn-slice");
  assert.equal(await disabled(page, "btn-download"), false);
  await page.click(".part-item:nth-child(1)");
  // the 20 mm cube at x = 140 on the 154 mm plate: 6 mm past its right edge
  await page.fill("#part-place_x", "140");
  await page.press("#part-place_x", "Enter");
  await page.waitForFunction(() => window.dropslice.job().offPlate.length === 1);
  const want = /^Part 1 “cube_20mm_ascii\.stl” reaches 6 mm past the plate's right edge — move it or press Arrange\.$/;
  assert.match((await job(page)).offPlate[0].message, want);
  assert.match(await page.locator("#settings-status").innerText(), want);
  assert.match(await page.locator("#parts-warnings").innerText(), want);
  assert.doesNotMatch(await page.locator("body").innerText(), /parts\[|bad job/i, "no programmer words");
  assert.equal(await disabled(page, "btn-download"), true);
  assert.equal(await disabled(page, "btn-share"), true);
  assert.equal(await disabled(page, "btn-slice"), true);
  // Enter in the settings (which slices) does not slice it either
  await page.press("#set-layer_height", "Enter");
  assert.notEqual((await status(page)).state, "slicing");
  assert.equal(await disabled(page, "btn-download"), true);
  // drawn in the warning colour: the parts list, the layer view's outline, the 3D view
  assert.equal(await page.locator(".part-item:nth-child(1)").getAttribute("data-off-plate"), "");
  await page.click("#mode-layer");
  await page.waitForFunction(() => document.getElementById("view").dataset.offPlate === "1");
  const view = await open3d(page);
  const id = `${(await job(page)).parts[0].id}:0`;
  assert.deepEqual(view.warned, [id]);
  // Arrange puts it back on the plate: sliceable again
  await page.click("#btn-arrange");
  await page.waitForFunction(() => window.dropslice.job().offPlate.length === 0);
  assert.equal(await disabled(page, "btn-slice"), false);
  assert.deepEqual((await page.evaluate(() => window.dropslice.view3d())).warned, []);
  assert.deepEqual(errors, []);
});

test("a link made in 3D opens in 3D with its camera, overlays and the note of the settings it changes", async () => {
  const { page, errors } = main;
  // one part: a page would open it in the layer view
  await clickSliced(page, "#btn-sample");
  await page.fill("#set-layer_height", "0.25");
  await clickSliced(page, "#btn-slice");
  await page.uncheck("#opt-below");
  await open3d(page);
  // orbit: a drag on the empty plate corner
  const r = await page.locator("#view3d canvas").boundingBox();
  await page.mouse.move(r.x + 30, r.y + r.height - 30);
  await page.mouse.down();
  await page.mouse.move(r.x + 130, r.y + r.height - 60, { steps: 6 });
  await page.mouse.up();
  const camera = await page.evaluate(() => window.dropslice.camera());
  const url = await shareLink(page);
  const other = await openPage(env.browser, url);
  await waitDone(other.page);
  await view3dReady(other.page);
  assert.equal(await other.page.getAttribute("#canvas-wrap", "data-mode"), "3d");
  await other.page.waitForFunction(
    (c) => {
      const got = window.dropslice.camera();
      return got && [...got.position, ...got.target].every((v, i) => Math.abs(v - [...c.position, ...c.target][i]) < 1e-6);
    },
    camera,
    { timeout: 10_000 },
  );
  assert.equal(await other.page.isChecked("#opt-below"), false, "the overlay toggles travel with the link");
  assert.equal(await other.page.isVisible("#link-from"), true);
  assert.match(await other.page.locator("#link-from").innerText(), /Opened from a preview link\.[\s\S]*layer height 0\.25 mm \(default 0\.2\)/);
  // the link carries the one setting changed, and no other differs (every default, those of
  // units 2 and 3 and `units` too, is the table's)
  assert.equal(await other.page.locator("#link-from-text").innerText(), "Settings that differ from the defaults: layer height 0.25 mm (default 0.2).");
  await other.page.click("#link-from-close");
  assert.equal(await other.page.isVisible("#link-from"), false);
  assert.deepEqual(other.errors, []);
  await other.context.close();
  await page.check("#opt-below");
  assert.deepEqual(errors, []);
});

test("a link carries the cut line; a link whose view numbers are wrong opens with them ignored and named", async () => {
  const { page, errors } = main;
  await page.click("#mode-layer");
  const line = { a: [2, 10], b: [18, 10] };
  assert.equal(await page.evaluate((l) => window.dropslice.cut().set(l), line), true);
  const url = await shareLink(page);
  const other = await openPage(env.browser, url);
  await waitDone(other.page);
  assert.equal(await other.page.getAttribute("#canvas-wrap", "data-mode"), "layer");
  await other.page.waitForFunction(() => window.dropslice.cut().status().line !== null);
  assert.deepEqual((await other.page.evaluate(() => window.dropslice.cut().status())).line, line);
  assert.equal(await other.page.isVisible("#cut-panel"), true);
  await other.context.close();
  // the same link with a camera far beyond any plate, a mode of its own, a cut of no length
  const hash = new URL(url).hash;
  const p = new URLSearchParams(hash.slice(1));
  const state = JSON.parse(inflateRawSync(Buffer.from(p.get("p"), "base64url")).toString());
  Object.assign(state, { mode: "<b>", camera: { position: [1e300, 0, 0], target: [0, 0, 0] }, cut: { a: [1, 1], b: [1, 1] }, overlays: { below: "no" } });
  p.set("p", deflateRawSync(Buffer.from(JSON.stringify(state))).toString("base64url"));
  const bad = await openPage(env.browser, `${url.split("#")[0]}#${p}`);
  await waitDone(bad.page);
  const banner = await bad.page.locator("#banner").innerText();
  for (const what of [/its view mode/, /its 3D camera/, /its cut line/, /its layer below overlay/]) assert.match(banner, what);
  assert.equal(await bad.page.getAttribute("#canvas-wrap", "data-mode"), "layer");
  assert.equal(await bad.page.evaluate(() => window.dropslice.cut().status().line), null);
  assert.deepEqual(bad.errors, []);
  await bad.context.close();
  await page.click("#cut-close");
  assert.deepEqual(errors, []);
});

test("a setting and the view survive a reload; Reset to defaults is undoable; a broken entry is ignored", async () => {
  const other = await openPage(env.browser, env.url);
  const { page, errors } = other;
  await waitDone(page, 60_000);
  await page.locator("#set-layer_height").evaluate((e) => (e.closest("details").open = true));
  await page.fill("#set-layer_height", "0.15");
  await page.check("#opt-travel");
  await page.waitForTimeout(500);
  await page.reload();
  await waitDone(page, 60_000);
  assert.equal(await page.inputValue("#set-layer_height"), "0.15");
  assert.equal(await page.isChecked("#opt-travel"), true);
  assert.match(await page.locator("#stat-droplet").innerText(), /× 0\.150 mm$/, "sliced with the remembered layer height");
  // Reset to defaults, then Ctrl+Z
  await page.click("#btn-reset");
  assert.equal(await page.inputValue("#set-layer_height"), "0.2");
  assert.match((await history(page)).undo, /reset settings to defaults/);
  await key(page, "Control+z");
  await page.waitForFunction(() => document.getElementById("set-layer_height").value === "0.15");
  // a hostile entry: out-of-range and wrong-typed values, unknown keys, then not JSON at all
  for (const entry of [
    '{"settings": {"layer_height": -5, "droplet_aspect": "1e999", "support": "everything", "plate_x": 1e300, "__proto__": {"x": 1}}, "view": {"mode": "<script>", "layer": -1, "travel": "yes"}}',
    "{not json",
  ]) {
    // written after the page's own (it remembers itself when it is left)
    await page.evaluate((e) => window.addEventListener("pagehide", () => localStorage.setItem("dropslice.page.v1", e)), entry);
    await page.reload();
    await waitDone(page, 60_000);
    assert.equal(await page.inputValue("#set-layer_height"), "0.2", `entry ${entry}`);
    assert.equal(await page.inputValue("#set-plate_x"), "154");
    assert.equal(await page.getAttribute("#canvas-wrap", "data-mode"), "layer");
  }
  assert.deepEqual(errors, []);
  await other.context.close();
});

test("calibration: after Use, a new slice does not suggest a new value from the same mass", async () => {
  const { page, errors } = main;
  await clickSliced(page, "#btn-sample");
  await page.click("#calib > summary");
  // a print 5 % lighter than the estimate
  const estimate = Number((await page.locator("#stat-mass").innerText()).replace(/ g$/, ""));
  await page.fill("#calib-mass", (estimate * 0.95).toFixed(3));
  await page.waitForFunction(() => document.getElementById("calib").dataset.state === "result");
  const suggested = await page.locator("#calib-aspect").innerText();
  assert.match(suggested, /^\d\.\d{3}$/);
  // the text and the button round alike
  assert.equal(await page.locator("#calib-use").innerText(), `Use droplet_aspect = ${suggested}`);
  assert.match(await page.locator("#calib-explanation").innerText(), new RegExp(`set droplet_aspect to ${suggested.replace(".", "\\.")} `));
  await page.click("#calib-use");
  assert.equal(await page.inputValue("#set-droplet_aspect"), String(Number(suggested)));
  assert.match(await page.locator("#calib-message").innerText(), /print the new code, weigh the print/);
  // slice the new code: the panel asks for a print of it, and suggests nothing from this mass
  await clickSliced(page, "#btn-slice");
  await page.waitForFunction(() => /earlier code/.test(document.getElementById("calib-source").innerText));
  assert.equal(await page.isVisible("#calib-result"), false);
  assert.equal(await page.isVisible("#calib-use"), false);
  assert.match(await page.locator("#calib-message").innerText(), new RegExp(`droplet_aspect is now ${suggested.replace(".", "\\.")}: print this new code, weigh the print`));
  assert.deepEqual(errors, []);
});

test("a link's settings are shown, not remembered over the visitor's own until they change one", async () => {
  const { page, errors } = main;
  await page.locator("#set-layer_height").evaluate((e) => (e.closest("details").open = true));
  const own = await page.inputValue("#set-layer_height");
  await page.fill("#set-layer_height", "0.3");
  await clickSliced(page, "#btn-slice");
  const url = await shareLink(page);
  await page.fill("#set-layer_height", own);
  await clickSliced(page, "#btn-slice");
  const other = await openPage(env.browser, url.split("#")[0]);
  const p = other.page;
  await waitDone(p, 60_000);
  await p.locator("#set-layer_height").evaluate((e) => (e.closest("details").open = true));
  await p.fill("#set-layer_height", "0.15");
  await p.waitForTimeout(500);
  // a stranger's link opened in the same browser, then the page again without it
  await p.goto("about:blank");
  await p.goto(url);
  await waitDone(p, 60_000);
  assert.equal(await p.inputValue("#set-layer_height"), "0.3", "the link's settings are shown");
  await p.goto("about:blank");
  await p.goto(url.split("#")[0]);
  await waitDone(p, 60_000);
  assert.equal(await p.inputValue("#set-layer_height"), "0.15", "the visitor's own settings were kept");
  // once the visitor changes a setting of the link's page, those are remembered
  await p.goto("about:blank");
  await p.goto(url);
  await waitDone(p, 60_000);
  await p.locator("#set-layer_height").evaluate((e) => (e.closest("details").open = true));
  await p.fill("#set-layer_height", "0.25");
  await p.waitForTimeout(500);
  await p.goto("about:blank");
  await p.goto(url.split("#")[0]);
  await waitDone(p, 60_000);
  assert.equal(await p.inputValue("#set-layer_height"), "0.25");
  assert.deepEqual(other.errors, []);
  await other.context.close();
  assert.deepEqual(errors, []);
});

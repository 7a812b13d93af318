// The tools a slicer's user reaches for first (issue 39): the skip links and landmarks (Slice
// and the layer view a few keys away), scale to a size in mm, mirror per axis, a part's context
// menu (the parts list and the 3D view, by mouse and keyboard), notices that go by themselves or
// on a click and never cover a control, the cut's position labelled. Needs dist/
// (scripts/build.sh).
import { after, before, test } from "node:test";
import assert from "node:assert/strict";
import { readFileSync } from "node:fs";
import { clientPoint3d, open3d, openPage, pixels3d, shareLink, startWithPage, stop, waitDone, waitSettled } from "./helpers.mjs";

let env;
let main;

before(async () => ({ env, main } = await startWithPage({ settle: true })));

after(() => stop(env));

const job = (page) => page.evaluate(() => window.dropslice.job());
const close = (a, b, tol = 1e-3) => Math.abs(a - b) <= tol;

/** Keys pressed from a fresh page's load until `id` has the focus: Tab until a skip link named
 *  `link` has it, then Enter. */
async function keysTo(link, id) {
  const { page } = await openPage(env.browser, env.url);
  await waitSettled(page, 60_000);
  let presses = 0;
  for (; presses < 20; ) {
    await page.keyboard.press("Tab");
    presses++;
    if ((await page.evaluate(() => document.activeElement?.id)) === link) break;
  }
  assert.equal(await page.evaluate(() => document.activeElement?.id), link);
  // the link shows when focused (it is off-screen otherwise)
  const box = await page.locator(`#${link}`).boundingBox();
  assert.ok(box && box.y >= 0 && box.height > 0, `the focused skip link is on screen: ${JSON.stringify(box)}`);
  await page.keyboard.press("Enter");
  presses++;
  assert.equal(await page.evaluate(() => document.activeElement?.id), id);
  await page.context().close();
  return presses;
}

test("skip links: Slice within 10 key presses of the page's load, the layer view within 15; landmarks", async () => {
  const toSlice = await keysTo("skip-slice", "btn-slice");
  assert.ok(toSlice <= 10, `${toSlice} presses to Slice`);
  const toLayer = await keysTo("skip-layer", "view");
  assert.ok(toLayer <= 15, `${toLayer} presses to the layer view`);
  const { page } = main;
  const marks = await page.evaluate(() => ({
    banner: document.querySelectorAll('header[role="banner"], body > header').length,
    nav: document.querySelectorAll('nav, [role="navigation"]').length,
    main: document.querySelectorAll('main, [role="main"]').length,
    aside: document.querySelectorAll('aside[role="complementary"]').length,
    first: document.querySelector("a[href], button, input, select, textarea, [tabindex]")?.id,
  }));
  assert.ok(marks.banner >= 1 && marks.nav >= 1 && marks.main === 1 && marks.aside === 2, JSON.stringify(marks));
  assert.equal(marks.first, "skip-slice", "the skip link is the first focusable element");
});

test("a size in mm per axis scales the part to it (uniform or one axis); a scale field takes 100mm", async () => {
  const { page, errors } = main;
  const size = async () => (await job(page)).layout.instances[0].size;
  const before = await job(page);
  const s0 = before.layout.instances[0].size;
  assert.equal(await page.inputValue("#part-size_x"), s0[0].toFixed(2));
  // uniform: all three scale together
  await page.check("#part-scale-lock");
  await page.fill("#part-size_x", "100mm");
  await page.press("#part-size_x", "Enter");
  await page.waitForFunction(() => Math.abs(window.dropslice.job().layout.instances[0].size[0] - 100) < 1e-3);
  const s1 = await size();
  for (const k of [1, 2]) assert.ok(close(s1[k], (s0[k] * 100) / s0[0], 1e-3), `${s1} from ${s0}`);
  const p1 = (await job(page)).parts[0];
  assert.ok(close(p1.scale_x, p1.scale_y, 1e-9) && close(p1.scale_y, p1.scale_z, 1e-9), JSON.stringify(p1));
  assert.equal(await page.inputValue("#part-size_x"), "100.00");
  // one axis
  await page.uncheck("#part-scale-lock");
  await page.fill("#part-size_y", "50");
  await page.press("#part-size_y", "Enter");
  await page.waitForFunction(() => Math.abs(window.dropslice.job().layout.instances[0].size[1] - 50) < 1e-3);
  assert.ok(close((await size())[0], 100), "x kept");
  // "100 mm" in a scale field is a size
  await page.fill("#part-scale_z", "30 mm");
  await page.press("#part-scale_z", "Enter");
  await page.waitForFunction(() => Math.abs(window.dropslice.job().layout.instances[0].size[2] - 30) < 1e-3);
  // refusals say what is wrong and change nothing
  const was = await job(page);
  for (const [text, why] of [["abc", /a size in mm is needed/], ["-5", /> 0 mm/], ["1000000", /scale must be > 0 and ≤ 1,000/]]) {
    await page.fill("#part-size_x", text);
    await page.press("#part-size_x", "Enter");
    assert.equal(await page.getAttribute("#part-size_x", "aria-invalid"), "true", text);
    assert.match(await page.getAttribute("#part-size_x", "title"), why);
  }
  assert.deepEqual((await job(page)).parts, was.parts);
  // back to the file's own scale, one axis after the other (each laid out before the next)
  await page.uncheck("#part-scale-lock");
  for (const k of ["x", "y", "z"]) {
    await page.fill(`#part-scale_${k}`, "1");
    await page.press(`#part-scale_${k}`, "Enter");
    await page.waitForFunction((k) => window.dropslice.job().parts[0][`scale_${k}`] === 1, k);
  }
  await page.check("#part-scale-lock");
  assert.deepEqual(errors, []);
});

test("mirror per axis: the toggle mirrors the part (its matrix), its size stays, it slices", async () => {
  const { page, errors } = main;
  const before = (await job(page)).layout.instances[0];
  await page.click("#part-mirror_x");
  await page.waitForFunction(() => window.dropslice.job().parts[0].mirror_x === true);
  assert.equal(await page.getAttribute("#part-mirror_x", "aria-pressed"), "true");
  const inst = (await job(page)).layout.instances[0];
  const m = inst.matrix;
  const det = m[0] * (m[5] * m[10] - m[9] * m[6]) - m[4] * (m[1] * m[10] - m[9] * m[2]) + m[8] * (m[1] * m[6] - m[5] * m[2]);
  assert.ok(det < 0, `determinant ${det}`);
  for (let k = 0; k < 3; k++) assert.ok(close(inst.size[k], before.size[k], 1e-6));
  // the job file says so (and only for the mirrored axis)
  const [d] = await Promise.all([page.waitForEvent("download"), page.click("#btn-save-job")]);
  const saved = JSON.parse(readFileSync(await d.path(), "utf8"));
  assert.equal(saved.parts[0].mirror_x, true);
  assert.equal("mirror_y" in saved.parts[0], false);
  // the slice of the mirrored part
  await page.evaluate(() => (document.body.dataset.state = "picking"));
  await page.click("#btn-slice");
  const s = await waitDone(page);
  assert.ok(s.droplets > 0);
  // a preview link carries the mirror
  const other = await openPage(env.browser, await shareLink(page));
  await waitDone(other.page);
  assert.equal((await job(other.page)).parts[0].mirror_x, true);
  assert.equal((await job(other.page)).parts[0].mirror_y, false);
  assert.equal((await other.page.evaluate(() => window.dropslice.status())).droplets, s.droplets);
  await other.context.close();
  // off again
  await page.click("#part-mirror_x");
  await page.waitForFunction(() => window.dropslice.job().parts[0].mirror_x === false);
  assert.equal(await page.getAttribute("#part-mirror_x", "aria-pressed"), "false");

  // lay flat through a z mirror puts the same face down: the first layer as large as the
  // plain part's (not the part standing on what was its top)
  const firstLayer = async () => {
    await page.evaluate(() => (document.body.dataset.state = "picking"));
    await page.click("#btn-slice");
    await waitDone(page);
    await page.evaluate(() => window.dropslice.show(0));
    await page.waitForFunction(() => window.dropslice.status().shown === 0);
    // the layer's droplets by role, added up
    const c = (await page.evaluate(() => window.dropslice.status())).layerDroplets;
    return typeof c === "number" ? c : Object.values(c).reduce((a, v) => a + (typeof v === "number" ? v : 0), 0);
  };
  const plain = await firstLayer();
  await page.click("#part-mirror_z");
  await page.waitForFunction(() => window.dropslice.job().parts[0].mirror_z === true);
  const upside = await firstLayer();
  await page.click("#part-lay-flat");
  // (the core's answer turns it; a page that kept the face up would change nothing)
  await page.waitForFunction(() => window.dropslice.job().parts[0].rotate_x !== 0, null, { timeout: 10_000 }).catch(() => {});
  const flat = await firstLayer();
  assert.ok(upside < 0.8 * plain, `mirrored along z the part stands on its top: ${upside} vs ${plain} droplets`);
  assert.ok(Math.abs(flat - plain) <= 0.05 * plain, `laid flat: ${flat} vs ${plain} droplets on the first layer`);
  // (one edit after the other: each is laid out by the core before the next)
  await page.click("#part-mirror_z");
  await page.waitForFunction(() => window.dropslice.job().parts[0].mirror_z === false);
  await page.fill("#part-rotate_x", "0");
  await page.press("#part-rotate_x", "Enter");
  await page.waitForFunction(() => {
    const p = window.dropslice.job().parts[0];
    return p.mirror_z === false && p.rotate_x === 0;
  });
  assert.deepEqual(errors, []);
});

test("a part's context menu: right-click or Shift+F10 in the list, right-click in 3D; arrows, Esc, focus back", async () => {
  const { page, errors } = main;
  // by mouse in the list
  await page.click(".part-item", { button: "right" });
  await page.waitForSelector("#part-menu:not([hidden])");
  const labels = await page.$$eval("#part-menu button", (bs) => bs.map((b) => b.textContent));
  assert.deepEqual(labels, ["Duplicate", "Remove", "Lay flat", "Orient…", "Mirror X", "Mirror Y", "Mirror Z", "Reset rotation, scale and mirror"]);
  assert.equal(await page.evaluate(() => document.activeElement?.id), "part-menu-duplicate", "the first item has the focus");
  await page.keyboard.press("Escape");
  assert.equal(await page.isVisible("#part-menu"), false);
  assert.equal(await page.evaluate(() => document.activeElement?.classList.contains("part-item")), true, "the focus is back on the part");
  // by keyboard: Shift+F10 on the focused line, arrows to Mirror Y, Enter
  await page.focus(".part-item");
  await page.keyboard.press("Shift+F10");
  await page.waitForSelector("#part-menu:not([hidden])");
  // Remove is disabled with one part (skipped by the arrows): Duplicate, Lay flat, Orient, Mirror X, Mirror Y
  for (let i = 0; i < 4; i++) await page.keyboard.press("ArrowDown");
  assert.equal(await page.evaluate(() => document.activeElement?.id), "part-menu-mirror-y");
  await page.keyboard.press("ArrowUp");
  await page.keyboard.press("ArrowDown");
  await page.keyboard.press("Enter");
  await page.waitForFunction(() => window.dropslice.job().parts[0].mirror_y === true);
  assert.equal(await page.isVisible("#part-menu"), false);
  assert.equal(await page.evaluate(() => document.activeElement?.classList.contains("part-item")), true, "the focus is back on the part");
  // the menu shows the mirror as checked; Reset clears rotation, scale and mirror
  await page.fill("#part-rotate_z", "30");
  await page.press("#part-rotate_z", "Enter");
  await page.waitForFunction(() => window.dropslice.job().parts[0].rotate_z === 30);
  await page.click(".part-item", { button: "right" });
  assert.equal(await page.getAttribute("#part-menu-mirror-y", "aria-checked"), "true");
  await page.click("#part-menu-reset");
  await page.waitForFunction(() => {
    const p = window.dropslice.job().parts[0];
    return p.rotate_z === 0 && p.mirror_y === false && p.scale_x === 1;
  });
  // Duplicate: a second part; then the menu's Remove is enabled and removes it
  await page.click(".part-item", { button: "right" });
  await page.click("#part-menu-duplicate");
  await page.waitForFunction(() => window.dropslice.job().parts.length === 2);

  // in 3D: a right-click on a part opens its menu (a right drag still pans)
  await open3d(page);
  const px = await pixels3d(page);
  const spot = px.part.inner ?? px.selected.inner;
  assert.ok(spot, "a part pixel to click");
  const at = await clientPoint3d(page, spot.x + 0.5, spot.y + 0.5);
  await page.mouse.click(at.x, at.y, { button: "right" });
  await page.waitForSelector("#part-menu:not([hidden])");
  const id = (await page.evaluate(() => window.dropslice.view3d())).selected;
  assert.ok(id !== null, "the part right-clicked is selected");
  assert.equal(await page.isDisabled("#part-menu-remove"), false);
  // Esc gives the focus back to the 3D view; Shift+F10 there opens the selected part's menu
  await page.keyboard.press("Escape");
  assert.equal(await page.evaluate(() => document.activeElement === document.querySelector("#view3d canvas")), true);
  await page.keyboard.press("Shift+F10");
  await page.waitForSelector("#part-menu:not([hidden])");
  await page.click("#part-menu-remove");
  await page.waitForFunction(() => window.dropslice.job().parts.length === 1);
  assert.equal(await page.isVisible("#part-menu"), false);
  await page.click("#mode-layer");
  // the shortcuts panel lists the menu's keys
  await page.click("#btn-shortcuts");
  const text = await page.locator("#shortcuts-dialog").innerText();
  for (const key of ["Shift+F10", "Right-click", "Skip to Slice"]) assert.ok(text.includes(key), `the panel lists ${key}`);
  await page.click("#shortcuts-close");
  assert.deepEqual(errors, []);
});

/** The page's visible controls (buttons, inputs, selects, sliders, focusable canvases) whose
 *  box meets `id`'s box, outside it. */
function coveredControls(page, id) {
  return page.evaluate((id) => {
    const n = document.getElementById(id);
    const a = n.getBoundingClientRect();
    const meets = (b) => b.width > 0 && b.height > 0 && a.left < b.right && b.left < a.right && a.top < b.bottom && b.top < a.bottom;
    return [...document.querySelectorAll('button, input, select, textarea, [role="slider"], canvas[tabindex], a[href]')]
      .filter((e) => !n.contains(e) && e.getClientRects().length > 0 && meets(e.getBoundingClientRect()))
      .map((e) => e.id || e.className || e.tagName);
  }, id);
}

test("notices cover no control; information goes by itself, an error stays until its ✕", async () => {
  const { page, errors } = main;
  // an undoable change, undone: the notice "Undone: …" with Redo
  await page.fill("#part-rotate_z", "45");
  await page.press("#part-rotate_z", "Enter");
  await page.waitForFunction(() => window.dropslice.job().parts[0].rotate_z === 45);
  await page.click("#btn-undo");
  await page.waitForSelector("#undo-note:not([hidden])");
  assert.deepEqual(await coveredControls(page, "undo-note"), []);
  // it goes by itself (8 s; the pointer is away from it)
  await page.mouse.move(5, 5);
  await page.waitForSelector("#undo-note", { state: "hidden", timeout: 15_000 });

  // an error: a job that does not fit; it stays past the information's time, goes on its ✕
  await page.fill("#part-copies", "100");
  await page.press("#part-copies", "Enter");
  await page.waitForSelector("#banner:not([hidden])");
  assert.deepEqual(await coveredControls(page, "banner"), []);
  await page.waitForTimeout(9_000);
  assert.equal(await page.isVisible("#banner"), true, "an error stays");
  await page.click("#banner-close");
  assert.equal(await page.isVisible("#banner"), false);
  assert.deepEqual(errors, []);
});

test("the cut's position is labelled on the layer view and in the cut panel", async () => {
  const { page, errors } = main;
  await page.evaluate(() => (document.body.dataset.state = "picking"));
  await page.click("#btn-slice");
  await waitDone(page);
  assert.equal(await page.evaluate(() => window.dropslice.cut().set({ a: [-1, 10.3], b: [21, 10.3] })), true);
  await page.waitForSelector("#cut-panel:not([hidden])");
  assert.equal(await page.textContent("#cut-where"), "Section along y = 10.30 mm, from A to B");
  await page.waitForFunction(() => document.getElementById("view").dataset.cutLabel === "y = 10.30 mm");
  assert.equal(await page.evaluate(() => window.dropslice.cut().set({ a: [5, -2], b: [5, 30] })), true);
  assert.equal(await page.textContent("#cut-where"), "Section along x = 5.00 mm, from A to B");
  assert.equal(await page.evaluate(() => window.dropslice.cut().set({ a: [0, 0], b: [10, 10] })), true);
  assert.equal(await page.textContent("#cut-where"), "Section along (0.00, 0.00) → (10.00, 10.00) mm, 45.0°, from A to B");
  await page.waitForFunction(() => document.getElementById("view").dataset.cutLabel === "(0.00, 0.00) → (10.00, 10.00) mm, 45.0°");
  await page.click("#cut-close");
  assert.deepEqual(errors, []);
});

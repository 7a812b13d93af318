// The page by keyboard, on small screens, and the figures that must agree (issue 24): the file
// pickers' buttons, the shortcuts panel, the plot as a slider, the layout at 800 and 390 px,
// the plot's count = *This layer* with support, the cut that crosses nothing, a .gco's time.
// Needs dist/ (scripts/build.sh).
import { after, before, test } from "node:test";
import assert from "node:assert/strict";
import { join } from "node:path";
import { downloadText, open3d, openPage, pick, shared, startWithPage, status, stop, waitDone } from "./helpers.mjs";

let env;
let main;

before(async () => ({ env, main } = await startWithPage({ settle: true })));

after(() => stop(env));

const overhang = join(shared, "models/U_overhang.obj");

/** Presses Tab from the top of the page until `id` has the focus (at most `most` times). */
async function tabTo(page, id, most = 40) {
  // a click on the page's name (not focusable) starts the Tab order at the top
  await page.evaluate(() => window.scrollTo(0, 0));
  await page.click(".brand .name");
  for (let i = 0; i < most; i++) {
    await page.keyboard.press("Tab");
    if ((await page.evaluate(() => document.activeElement?.id)) === id) return i + 1;
  }
  assert.fail(`Tab never reached #${id}`);
}

/** The number in a text like "2,354" or "Layer 3 · … · 2,354 droplets …" (the one before
 *  "droplets" when there is one). */
function count(text) {
  const m = /([\d,]+) droplets/.exec(text) ?? /^([\d,]+)$/.exec(text.trim());
  assert.ok(m, `no count in ${JSON.stringify(text)}`);
  return Number(m[1].replaceAll(",", ""));
}

/** "2 h 10 min" / "3 min 5 s" / "40 s" → seconds. */
function seconds(text) {
  const m = /^(?:(\d+) h )?(?:(\d+) min)? ?(?:(\d+) s)?$/.exec(text.trim());
  assert.ok(m && text.trim() !== "", `not a duration: ${JSON.stringify(text)}`);
  return Number(m[1] ?? 0) * 3600 + Number(m[2] ?? 0) * 60 + Number(m[3] ?? 0);
}

/** The file chooser that pressing `key` opens. The listener is in place (Playwright turns the
 *  chooser's interception on when the first listener is added; a round trip lets that land)
 *  before the key is pressed. */
async function chooserOf(page, key) {
  const chooser = page.waitForEvent("filechooser", { timeout: 5000 });
  await page.evaluate(() => 1);
  await page.keyboard.press(key);
  return chooser;
}

test("Tab reaches Open models and Add part; Enter and Space open the file pickers", async () => {
  const { page, errors } = main;
  await tabTo(page, "btn-open");
  const chooser = await chooserOf(page, "Enter");
  assert.equal(chooser.isMultiple(), true);
  assert.equal(await chooser.element().evaluate((e) => e.id), "file-input");
  await chooser.setFiles([]);

  // the sample is a job: its parts panel has Add part…
  await tabTo(page, "btn-add", 80);
  const add = await chooserOf(page, " ");
  assert.equal(await add.element().evaluate((e) => e.id), "add-input");
  await add.setFiles([]);
  // the hint over an empty stage reads as a sentence (it is a flex box: its text in one item)
  const hint = await page.evaluate(() => {
    const e = document.getElementById("empty");
    const was = e.hidden;
    e.hidden = false;
    const text = e.innerText;
    e.hidden = was;
    return text;
  });
  assert.equal(hint, "Drop STL, OBJ or 3MF files here, or use Open models.");
  assert.deepEqual(errors, []);
});

test("? opens the shortcuts panel listing every key; Esc closes it and the focus goes back", async () => {
  const { page } = main;
  await tabTo(page, "btn-sample");
  await page.keyboard.press("?");
  await page.waitForSelector("#shortcuts-dialog[open]");
  const text = await page.locator("#shortcuts-dialog").innerText();
  for (const key of ["Ctrl+Z", "Ctrl+Shift+Z or Ctrl+Y", "Delete", "Home / End", "Page Up / Page Down", "F", "→ or ↑", "← or ↓", "Esc", "?"]) {
    assert.ok(text.includes(key), `the panel lists ${key}: ${text}`);
  }
  await page.keyboard.press("Escape");
  await page.waitForSelector("#shortcuts-dialog:not([open])", { state: "attached" });
  assert.equal(await page.evaluate(() => document.activeElement?.id), "btn-sample");

  // "?" typed into a setting is a character, not the panel
  await page.focus("#settings input[type=text]");
  await page.keyboard.press("?");
  assert.equal(await page.locator("#shortcuts-dialog[open]").count(), 0);
  await page.keyboard.press("Backspace");

  // the visible button opens it too
  await page.click("#btn-shortcuts");
  await page.waitForSelector("#shortcuts-dialog[open]");
  await page.click("#shortcuts-close");
  await page.waitForSelector("#shortcuts-dialog:not([open])", { state: "attached" });
  assert.equal(await page.evaluate(() => document.activeElement?.id), "btn-shortcuts");
});

test("the plot is a slider for the keyboard: Tab reaches it, arrows move the layer, its value says so", async () => {
  const { page } = main;
  await tabTo(page, "plot", 120);
  const before = (await status(page)).layer;
  await page.keyboard.press("ArrowRight");
  await page.keyboard.press("ArrowRight");
  await page.keyboard.press("ArrowLeft");
  const s = await status(page);
  assert.equal(s.layer, before + 1);
  await page.waitForFunction((n) => document.getElementById("plot").getAttribute("aria-valuenow") === String(n), s.layer + 1);
  const text = await page.locator("#plot").getAttribute("aria-valuetext");
  assert.match(text, new RegExp(`^Layer ${s.layer + 1} `));
  const c = s.layerDroplets;
  assert.equal(count(text), c.outer + c.inner + c.fill + c.support);
});

test("with support on, the plot's count of a layer is This layer's, support included, and drawn stacked", async () => {
  const { page, errors } = main;
  await page.check("#opt-support");
  await pick(page, overhang);
  const s = await waitDone(page);
  assert.ok(s.counts.support > 0, `the model needs support: ${JSON.stringify(s.counts)}`);
  const per = await page.evaluate(() => window.dropslice.layerUnits());
  const withSupport = per.map((u, i) => [u?.[0] ?? 0, i]).filter(([n]) => n > 0).map(([, i]) => i);
  assert.ok(withSupport.length > 3, `layers with support: ${withSupport.length}`);
  const checked = [withSupport[0], withSupport[Math.floor(withSupport.length / 2)], withSupport.at(-1), s.layers - 1];
  await page.mouse.move(2, 2); // no hover: the label is the current layer's
  for (const i of checked) {
    await page.evaluate((k) => window.dropslice.show(k), i);
    await page.waitForFunction((k) => document.getElementById("plot-label").textContent.startsWith(`Layer ${k + 1} `), i);
    const label = await page.locator("#plot-label").innerText();
    const layer = count(await page.locator("#stat-layer-droplets").innerText());
    assert.equal(count(label), layer, `layer ${i + 1}: plot "${label}" vs This layer ${layer}`);
    const c = (await status(page)).layerDroplets;
    assert.equal(layer, c.outer + c.inner + c.fill + c.support, `layer ${i + 1}: the core's counts`);
    if (per[i][0] > 0) {
      assert.ok(count(label) > c.outer + c.inner + c.fill, `layer ${i + 1}: the support is counted`);
      assert.match(label, new RegExp(`${per[i][0].toLocaleString("en-US")} support`));
    }
  }
  // the legend names the support, and the plot has bars in its colour (#86d0dc)
  assert.equal(await page.locator("#plot-key-support").isVisible(), true);
  const supportPixels = await page.evaluate(() => {
    const c = document.getElementById("plot");
    const d = c.getContext("2d").getImageData(0, 0, c.width, c.height).data;
    let n = 0;
    for (let i = 0; i < d.length; i += 4) if (d[i] === 0x86 && d[i + 1] === 0xd0 && d[i + 2] === 0xdc) n++;
    return n;
  });
  assert.ok(supportPixels > 200, `support bars: ${supportPixels} px`);

  // the 3D view draws the support (columns of the layers' support droplets) beside the part
  await open3d(page);
  await page.waitForFunction(() => (window.dropslice.view3d()?.support ?? 0) > 0, null, { timeout: 30_000 });
  assert.equal(await page.locator("#legend3d-support").isVisible(), true);
  await page.click("#mode-layer");
  assert.deepEqual(errors, []);
});

test("a cut beside the part says it crosses no part; a dragged cut fills the position field", async () => {
  const { page } = main;
  await page.click("#btn-cut");
  await page.waitForSelector("#cut-panel:not([hidden])");
  // the default line crosses the part: no message, and the field says where it is
  await page.waitForFunction(() => window.dropslice.cut().status().pending === 0 && window.dropslice.cut().status().resolved > 0, null, { timeout: 60_000 });
  assert.equal(await page.locator("#cut-missed").isVisible(), false);
  assert.notEqual(await page.inputValue("#cut-pos"), "");

  // y = 500 mm: far beside the part
  await page.selectOption("#cut-axis", "y");
  await page.fill("#cut-pos", "500");
  await page.click("#cut-apply");
  await page.waitForSelector("#cut-missed:not([hidden])", { timeout: 10_000 });
  assert.equal(await page.locator("#cut-missed").innerText(), "The cut line crosses no part — drag it across a part.");

  // dragged across the part with the Cut tool: the field shows the line's position
  const box = await page.locator("#view").boundingBox();
  const y = box.y + box.height * 0.5;
  await page.mouse.move(box.x + box.width * 0.3, y);
  await page.mouse.down();
  await page.mouse.move(box.x + box.width * 0.7, y + 2, { steps: 6 });
  await page.mouse.up();
  const line = (await page.evaluate(() => window.dropslice.cut().status())).line;
  assert.ok(line, "a line was drawn");
  assert.equal(await page.inputValue("#cut-axis"), "y");
  const mid = (line.a[1] + line.b[1]) / 2;
  assert.ok(Math.abs(Number(await page.inputValue("#cut-pos")) - mid) < 0.01, `field ${await page.inputValue("#cut-pos")} vs ${mid}`);
  await page.waitForFunction(() => window.dropslice.cut().status().pending === 0, null, { timeout: 60_000 });
  assert.equal(await page.locator("#cut-missed").isVisible(), false);
  await page.click("#cut-close");
});

test("a .gco opened for viewing shows the time and material of its header", async () => {
  const { page } = main;
  const sliced = {
    time: await page.locator("#stat-time").innerText(),
    travel: await page.locator("#stat-travel").innerText(),
    mass: await page.locator("#stat-mass").innerText(),
    volume: await page.locator("#stat-volume").innerText(),
  };
  const code = await downloadText(page);
  await pick(page, { name: "overhang.gco", mimeType: "text/plain", buffer: Buffer.from(code) });
  await waitDone(page);
  assert.equal(await page.locator("#stat-model").innerText(), "overhang.gco");
  // the header's figures: the slice's own, travel included
  assert.ok(seconds(sliced.time) > 0, sliced.time);
  assert.equal(await page.locator("#stat-time").innerText(), sliced.time);
  assert.equal(await page.locator("#stat-travel").innerText(), sliced.travel);
  assert.equal(await page.locator("#stat-mass").innerText(), sliced.mass);
  assert.equal(await page.locator("#stat-volume").innerText(), sliced.volume);
});

test("at 800 × 900 the panels stack: settings at least 200 px high, the print time scrolls into view", async () => {
  const other = await openPage(env.browser, env.url, { width: 800, height: 900 });
  const { page, errors } = other;
  await waitDone(page, 60_000);
  const settings = await page.locator("aside.settings").boundingBox();
  assert.ok(settings.height >= 200, `settings ${settings.height} px high`);
  const time = page.locator("#stat-time");
  await time.scrollIntoViewIfNeeded();
  const box = await time.boundingBox();
  assert.ok(box.y >= 0 && box.y + box.height <= 900 && box.x + box.width <= 800, `print time at ${JSON.stringify(box)}`);
  seconds(await time.innerText());
  // the element at the time's place is the time (nothing covers it)
  const top = await page.evaluate(({ x, y }) => document.elementFromPoint(x, y)?.id, { x: box.x + box.width / 2, y: box.y + box.height / 2 });
  assert.equal(top, "stat-time");
  assert.ok(await page.evaluate(() => document.documentElement.scrollWidth <= window.innerWidth));
  assert.deepEqual(errors, []);
  await other.context.close();
});

test("at 390 px nothing overflows sideways, with a slice with support and the cut open", async () => {
  const other = await openPage(env.browser, env.url, { width: 390, height: 844 });
  const { page, errors } = other;
  await waitDone(page, 60_000);
  await page.check("#opt-support");
  await pick(page, overhang);
  await waitDone(page);
  await page.click("#btn-cut");
  await page.waitForSelector("#cut-panel:not([hidden])");
  await page.click("#btn-shortcuts");
  await page.waitForSelector("#shortcuts-dialog[open]");
  const wide = await page.evaluate(() => ({
    scroll: document.documentElement.scrollWidth,
    inner: window.innerWidth,
    over: [...document.querySelectorAll("body *")]
      .filter((e) => e.getBoundingClientRect().width > 0 && e.getBoundingClientRect().right > window.innerWidth + 0.5)
      .map((e) => e.id || e.className),
  }));
  assert.ok(wide.scroll <= wide.inner, `scrollWidth ${wide.scroll} > ${wide.inner}: ${wide.over.join(", ")}`);
  assert.deepEqual(wide.over, []);
  await page.keyboard.press("Escape");
  assert.deepEqual(errors, []);
  await other.context.close();
});

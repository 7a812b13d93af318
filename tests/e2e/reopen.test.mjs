// Re-opening the page's own .gco (issue "The user's work survives"): the statistics show the
// very figures of the slice that wrote it (its header's: time, travel, volume, mass, the
// droplets by role, with the slice's role names), the settings form shows the file's settings
// (or says how it differs), a file without those header lines says its figures come from its
// moves, and a filament printer's .gcode is named as such. Needs dist/ (scripts/build.sh).
import { after, before, test } from "node:test";
import assert from "node:assert/strict";
import { mkdtempSync, writeFileSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { downloadText, pick, shared, startWithPage, stop, waitDone, waitSettled } from "./helpers.mjs";

let env;
let main;
const tmp = mkdtempSync(join(tmpdir(), "dropslice-reopen-"));

before(async () => ({ env, main } = await startWithPage({ settle: true })));

after(() => stop(env, tmp));

const FIGURES = ["stat-volume", "stat-mass", "stat-time", "stat-travel", "stat-outer", "stat-inner", "stat-fill", "stat-droplets", "stat-label-0", "stat-label-2"];

/** The statistics panel's texts of `FIGURES`. */
const shown = (page) => page.evaluate((ids) => Object.fromEntries(ids.map((id) => [id, document.getElementById(id).innerText])), FIGURES);

/** Types `value` into the settings form's field `name`. */
async function setField(page, name, value) {
  await page.fill(`#set-${name}`, value);
  await page.dispatchEvent(`#set-${name}`, "change");
}

let sliced; // the figures shown after slicing with droplet_aspect 1.3
let code; // the code downloaded then

test("re-opening a downloaded .gco shows exactly the slice's figures and role names", async () => {
  const { page, errors } = main;
  await setField(page, "droplet_aspect", "1.3");
  await page.evaluate(() => (document.body.dataset.state = "picking"));
  await page.click("#btn-slice");
  await waitDone(page, 120_000);
  await waitSettled(page);
  sliced = await shown(page);
  assert.equal(sliced["stat-label-0"], "Outer loop");
  assert.notEqual(sliced["stat-inner"], "0");
  assert.match(sliced["stat-time"], /\d/);
  code = await downloadText(page);
  assert.match(code, /^; droplet_aspect = 1\.3$/m);
  assert.match(code, /^; print time {11}= +[\d.e-]+ s$/m);
  assert.match(code, /^; travel {15}= +[\d.e-]+ mm$/m);
  const file = join(tmp, "sample.gco");
  writeFileSync(file, code);
  // another aspect in the form: opening the file shows the file's
  await setField(page, "droplet_aspect", "1.04");
  await pick(page, file);
  const s = await waitDone(page);
  assert.equal(s.name, "sample.gco");
  assert.deepEqual(await shown(page), sliced);
  assert.equal(await page.locator("#figures-note").isHidden(), true);
  assert.equal(await page.locator("#stat-support-label").isHidden(), false);
  assert.deepEqual(errors, []);
});

test("the settings form shows the opened .gco's settings, or says how it differs", async () => {
  const { page } = main;
  assert.ok(code, "the test before downloaded the code");
  assert.equal(await page.inputValue("#set-droplet_aspect"), "1.3");
  const note = page.locator("#form-source");
  assert.equal(await note.innerText(), "The settings form shows the settings of “sample.gco” (from its header).");
  await setField(page, "droplet_aspect", "1.1");
  assert.equal(await note.innerText(), "The settings form differs from “sample.gco”: droplet_aspect is 1.1 here, 1.3 in the file.");
  // back at the file's value: the form says so again
  await setField(page, "droplet_aspect", "1.3");
  assert.equal(await page.getAttribute("#form-source", "data-state"), "file");
});

test("a .gco without the header's figures says they come from its moves", async () => {
  const { page } = main;
  assert.ok(code, "the first test downloaded the code");
  const older = code
    .split("\n")
    .filter((l) => !/^; (print time|travel|volume|mass) /.test(l))
    .join("\n");
  const file = join(tmp, "older.gco");
  writeFileSync(file, older);
  await pick(page, file);
  await waitDone(page);
  const got = await shown(page);
  assert.equal(got["stat-label-0"], "Loop droplets (G26)");
  assert.equal(got["stat-label-2"], "Fill lines (G25)");
  assert.equal(got["stat-droplets"], sliced["stat-droplets"], "the same droplets in all");
  assert.equal(await page.locator("#figures-note").innerText(), "Computed from the file's moves: the header has no figures (a code of an earlier dropslice, or of another program).");
});

test("a filament printer's .gcode is named as such", async () => {
  const { page } = main;
  const fdm = ";FLAVOR:Marlin\n;Generated with Cura_SteamEngine 5.6.0\nM140 S60\nM105\nM190 S60\nM104 S200\nG28\nG92 E0\nG1 F1500 E-6.5\nG1 X10 Y20 Z0.3 E1.2\n";
  const file = join(tmp, "benchy_PLA.gcode");
  writeFileSync(file, fdm);
  await pick(page, file);
  const s = await waitSettled(page);
  assert.equal(s.state, "error");
  const banner = await page.locator("#banner").innerText();
  assert.match(banner, /line 3: this is G-code for another kind of printer \(it has M140, M105, M190, G1 … E…\): dropslice reads the droplet printer's code it writes \(G01 travel, G25 droplet line, G26 droplet\)/);
  assert.doesNotMatch(banner, /is not a G01, G25 or G26 command/);
});

test("two units: the re-opened .gco shows each unit's figures of the slice", async () => {
  const { page, errors } = main;
  await page.check("#opt-support");
  await pick(page, join(shared, "models/U_overhang.obj"));
  await waitDone(page, 120_000);
  await waitSettled(page);
  const ids = [...FIGURES, "stat-support", "stat-unit1", "stat-volume1", "stat-mass1", "stat-unit-times"];
  const texts = () => page.evaluate((ids) => Object.fromEntries(ids.map((id) => [id, document.getElementById(id).innerText])), ids);
  const two = await texts();
  assert.notEqual(two["stat-support"], "0", "the part needs support");
  assert.match(two["stat-unit-times"], /·/);
  const text = await downloadText(page);
  assert.match(text, /^; volume unit 1 {8}= +[\d.e-]+ mm³$/m);
  const file = join(tmp, "u.gco");
  writeFileSync(file, text);
  await page.uncheck("#opt-support");
  await pick(page, file);
  await waitDone(page);
  assert.deepEqual(await texts(), two);
  assert.equal(await page.isChecked("#opt-support"), true, "the form takes the file's support = unit1");
  assert.deepEqual(errors, []);
});

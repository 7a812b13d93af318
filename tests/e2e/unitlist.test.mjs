// Discharge units as a list in the page (issue 41): with the two units of today's settings
// every per-unit control shows units 0 and 1 (the parts panel's choice, the form's "Unit 1"
// group, the support switch); a material profile holds one material and asks which unit it is
// for (a button per unit), one saved before with `unit1_` keys is used as it was. With a core
// that has the setting `units`: one unit hides unit 1's controls, three give a third unit its
// choice, group, droplets, colour and legends. Needs dist/ (scripts/build.sh).
import { after, before, test } from "node:test";
import assert from "node:assert/strict";
import { copyFileSync, existsSync, mkdtempSync, readFileSync, writeFileSync } from "node:fs";
import { execFileSync } from "node:child_process";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { pathToFileURL } from "node:url";
import { benchy, countPixels, downloadText, pick, repo, shared, startWithPage, stop, twoCubesSecondOnUnit, waitDone } from "./helpers.mjs";

let env;
let main;
const tmp = mkdtempSync(join(tmpdir(), "dropslice-unitlist-"));

// whether the core has the setting `units` (a core before it has two units, unnamed)
const core = await import(pathToFileURL(join(repo, "www", "pkg", "dropslice.js")).href);
await core.default({ module_or_path: readFileSync(join(repo, "www", "pkg", "dropslice_bg.wasm")) });
const hasUnits = core.settings_schema().some((s) => s.name === "units");

before(async () => ({ env, main } = await startWithPage({ settle: true })));

after(() => stop(env, tmp));

/** Types (or picks, for a list) a setting's value in the form, as a user does. */
async function setField(page, name, value) {
  const sel = `#settings [name="${name}"]`;
  const tag = await page.$eval(sel, (el) => {
    for (let d = el.closest("details"); d; d = d.parentElement?.closest("details")) d.open = true;
    return el.tagName;
  });
  if (tag === "SELECT") await page.selectOption(sel, String(value));
  else {
    await page.fill(sel, String(value));
    await page.press(sel, "Tab");
  }
}

const field = (page, name) => page.inputValue(`#settings [name="${name}"]`);
const options = (page, sel) => page.$$eval(`${sel} option`, (os) => os.map((o) => [o.value, o.textContent]));
/** The form's groups as shown: their titles, hidden ones left out. */
const groups = (page) => page.$$eval("#settings details.group", (ds) => ds.filter((d) => !d.hidden).map((d) => d.querySelector("summary").textContent));

test("two units: the parts panel, the form and the support switch show units 0 and 1", async () => {
  const { page, errors } = main;
  await page.click(".part-item:nth-child(1)");
  assert.deepEqual(await options(page, "#part-unit"), [
    ["0", "Unit 0 (main material)"],
    ["1", "Unit 1 (second material)"],
  ]);
  assert.equal(await page.isVisible("#part-unit"), true);
  assert.equal(await page.isVisible("#support-switch"), true);
  assert.equal(await page.locator("#opt-support-name").innerText(), "Support (unit 1)");
  const shown = await groups(page);
  assert.ok(shown.includes("Unit 1"), shown.join(", "));
  assert.ok(!shown.includes("Unit 2"));
  // every unit1_ row sits in the group "Unit 1"
  const misplaced = await page.$$eval('#settings [name^="unit1_"]', (els) => els.filter((e) => e.closest("details")?.querySelector("summary")?.textContent !== "Unit 1").map((e) => e.name));
  assert.deepEqual(misplaced, []);
  // the statistics' unit rows: unit 1's, no other
  assert.equal(await page.locator("#stat-unit1").count(), 1);
  assert.equal(await page.locator("#stat-unit2").count(), 0);
  assert.deepEqual(errors, []);
});

test("a material profile holds one material: saved from a unit, used for the unit picked; an older one as before", async () => {
  const { page, errors } = main;
  await page.click("#profiles summary");
  await setField(page, "unit1_droplet_aspect", 1.5);
  await setField(page, "unit1_material_density", 1.3);
  const aspect0 = await field(page, "droplet_aspect");
  // saved from unit 1: the save row asks whose material
  await page.selectOption("#profile-kind", "material");
  assert.equal(await page.isVisible("#profile-unit"), true);
  assert.deepEqual(await options(page, "#profile-unit"), [
    ["0", "of unit 0"],
    ["1", "of unit 1"],
  ]);
  await page.selectOption("#profile-unit", "1");
  await page.fill("#profile-name", "PC");
  await page.click("#profile-save");
  await page.waitForSelector('#profile-list li[data-name="PC"]');
  const kept = await page.evaluate(() => JSON.parse(localStorage.getItem("dropslice.profiles.v1")).find((p) => p.name === "PC"));
  assert.equal(kept.kind, "material");
  assert.equal(kept.settings.droplet_aspect, 1.5);
  assert.equal(kept.settings.material_density, 1.3);
  assert.ok(Object.keys(kept.settings).every((k) => !/^unit\d+_/.test(k)), `no unit in the keys: ${Object.keys(kept.settings)}`);

  // back to the defaults, then used for unit 0: a button per unit
  await page.click("#btn-reset");
  assert.equal(await field(page, "unit1_droplet_aspect"), "1.04");
  await page.click('#profile-list li[data-name="PC"] .profile-use');
  const buttons = await page.$$eval("#profile-list .profile-units .profile-unit", (bs) => bs.map((b) => [b.dataset.unit, b.textContent]));
  assert.deepEqual(buttons, [
    ["0", "Unit 0"],
    ["1", "Unit 1"],
  ]);
  assert.equal(await field(page, "droplet_aspect"), aspect0, "nothing set before a unit is picked");
  await page.click('#profile-list .profile-unit[data-unit="0"]');
  assert.equal(await field(page, "droplet_aspect"), "1.5");
  assert.equal(await field(page, "unit1_droplet_aspect"), "1.04", "unit 1 keeps its material");
  assert.equal(await page.locator("#profile-list .profile-units").count(), 0);
  // then for unit 1: unit 0 keeps what it has
  await page.click('#profile-list li[data-name="PC"] .profile-use');
  await page.click('#profile-list .profile-unit[data-unit="1"]');
  assert.equal(await field(page, "unit1_droplet_aspect"), "1.5");
  assert.equal(await field(page, "unit1_material_density"), "1.3");
  assert.equal(await field(page, "droplet_aspect"), "1.5");
  assert.equal((await page.evaluate(() => window.dropslice.history())).undo, "use profile PC for unit 1");
  // Escape closes the question without using the profile
  await page.click('#profile-list li[data-name="PC"] .profile-use');
  await page.keyboard.press("Escape");
  assert.equal(await page.locator("#profile-list .profile-units").count(), 0);

  // a material profile saved before (both units' keys, as the page saved them): used at once,
  // each value where it went before
  const old = join(tmp, "old.material.json");
  writeFileSync(old, JSON.stringify({ name: "Old", kind: "material", settings: { droplet_aspect: 1.1, material_density: 1.2, unit1_droplet_aspect: 1.7, unit1_material_density: 1.25 } }));
  await page.setInputFiles("#profile-file", old);
  await page.waitForSelector('#profile-list li[data-name="Old"]', { timeout: 30_000 });
  await page.click('#profile-list li[data-name="Old"] .profile-use');
  assert.equal(await page.locator("#profile-list .profile-units").count(), 0, "no unit asked");
  assert.equal(await field(page, "droplet_aspect"), "1.1");
  assert.equal(await field(page, "unit1_droplet_aspect"), "1.7");
  assert.equal(await field(page, "unit1_material_density"), "1.25");
  await page.click("#btn-reset");
  assert.deepEqual(errors, []);
});

test("one unit hides unit 1's controls; three give unit 2 its choice and group", { skip: !hasUnits && "the core has no setting `units` yet" }, async () => {
  const { page, errors } = main;
  await setField(page, "units", 1);
  await page.click(".part-item:nth-child(1)");
  assert.equal(await page.isVisible("#part-unit"), false, "no unit to choose");
  assert.equal(await page.isVisible("#support-switch"), false, "no unit for support");
  assert.ok(!(await groups(page)).includes("Unit 1"));
  // The statistics describe the slice: sliced with one unit, no row of unit 1.
  await page.click("#btn-slice");
  const one = await waitDone(page);
  assert.equal(one.units, 1);
  assert.equal(await page.locator("#stat-unit1").count(), 0);

  await setField(page, "units", 3);
  await page.waitForFunction(() => document.querySelectorAll("#part-unit option").length === 3);
  assert.deepEqual((await options(page, "#part-unit"))[2], ["2", "Unit 2 (third material)"]);
  assert.equal(await page.isVisible("#support-switch"), true);
  if (await page.locator('#settings [name^="unit2_"]').count()) assert.ok((await groups(page)).includes("Unit 2"));
  await setField(page, "units", 2);
  assert.deepEqual(errors, []);
});

// Every unit prints: a part of unit 2 on a machine of three units, then two materials and
// the support from unit 2.
test("three units print a unit-2 part with its droplets and colour", async () => {
  const { page, errors } = main;
  await setField(page, "units", 3);
  await page.waitForFunction(() => document.querySelectorAll("#part-unit option").length === 3);
  // two cubes, the second printed by unit 2
  await twoCubesSecondOnUnit(page, tmp, 2);
  await page.click("#btn-slice");
  const s = await waitDone(page);
  assert.equal(s.units, 3);
  assert.equal(s.unitDroplets.length, 3);
  assert.ok(s.unitDroplets[2] > 0, `unit 2's droplets ${s.unitDroplets}`);
  assert.equal(s.unitDroplets[1], 0);
  const shown = Number((await page.locator("#stat-unit2").innerText()).replace(/[^\d]/g, ""));
  assert.equal(shown, s.unitDroplets[2]);
  assert.equal(await page.locator("#stat-unit-times-label").innerText(), "Droplet time, unit 0 · 2", "the units that print");
  assert.equal(await page.isVisible("#stat-mass2"), true);
  assert.equal(await page.isVisible("#stat-mass1"), false);
  assert.equal(await page.isVisible("#plot-key-unit2"), true);
  assert.equal(await page.isVisible("#plot-key-unit1"), false);
  // the unit-0 part selected: the unit-2 part is drawn untinted
  await page.click(".part-item:nth-child(1)");
  await page.click("#mode-layer");
  await page.evaluate((i) => window.dropslice.show(i), Math.floor(s.layers / 2));
  await page.click("#btn-fit");
  await page.waitForTimeout(200);
  assert.equal(await page.isVisible("#legend-unit2"), true);
  // unit 2's droplets in its colour (#6b4226, within a few levels: the selected part is tinted)
  const unit2 = "Math.abs(r - 0x6b) < 12 && Math.abs(g - 0x42) < 12 && Math.abs(b - 0x26) < 12";
  assert.ok((await countPixels(page, unit2)) > 300, "the unit-2 part in its colour");

  // two materials (3DBenchy by unit 0, the cube by unit 1) and the support from unit 2
  await pick(page, [benchy, join(tmp, "cube-a.stl")]);
  await waitDone(page);
  await page.click(".part-item:nth-child(2)");
  await page.selectOption("#part-unit", "1");
  await page.waitForFunction(() => window.dropslice.job().parts[1].unit === 1);
  await setField(page, "support", "unit2");
  await page.click("#btn-slice");
  const t = await waitDone(page);
  assert.ok(t.counts.support > 0, `support droplets ${t.counts.support}`);
  assert.equal(t.unitDroplets[2], t.counts.support, "unit 2 prints the support and nothing else");
  assert.ok(t.unitDroplets[1] > 0 && t.unitDroplets[0] > 0, `${t.unitDroplets}`);
  const code = await downloadText(page);
  assert.ok(code.includes("\nT2\n") && code.includes("\nT1\n"), "T1 and T2 lines");
  assert.match(code, new RegExp(`; droplets of unit 2 += +${t.unitDroplets[2]}\\n`));
  assert.match(code, new RegExp(`; droplets of unit 1 += +${t.unitDroplets[1]}\\n`));
  assert.deepEqual(errors, []);
});

// The three-unit job of tests/two_material.rs (3DBenchy by unit 0, a cube by unit 1 with wider
// droplets, the support from unit 2 with droplets of its own, `unit_order = 1,2,0`), opened in
// the page as a job file: the page's .gco is the command line's, byte for byte. That test holds
// the command line's code to the oracle's sections unit by unit, so the page's is held to them
// too.
test("a three-unit job file: the page's .gco is the command line's, byte for byte", async (t) => {
  const cli = join(repo, "target/release/dropslice");
  if (!existsSync(cli)) return t.skip("target/release/dropslice not built");
  if (!hasUnits) return t.skip("the core has no setting `units`");
  const { page, errors } = main;
  const job = {
    settings: { units: 3, support: "unit2", unit_order: "1,2,0", unit1_droplet_aspect: 1.6, unit2_droplet_aspect: 1.3, unit2_material_density: 1.5 },
    parts: [
      { file: "3DBenchy.stl", place_x: 5, place_y: 5, unit: 0 },
      { file: "cube_20mm_ascii.stl", place_x: 75, place_y: 5, unit: 1 },
    ],
  };
  const jobFile = join(tmp, "three-units.json");
  writeFileSync(jobFile, JSON.stringify(job));
  for (const f of ["3DBenchy.stl", "cube_20mm_ascii.stl"]) copyFileSync(join(shared, "models", f), join(tmp, f));
  const out = join(tmp, "three-units.gco");
  execFileSync(cli, [jobFile, "-o", out, "-q"], { stdio: "inherit" });
  const theirs = readFileSync(out, "utf8");

  await pick(page, [jobFile, join(tmp, "3DBenchy.stl"), join(tmp, "cube_20mm_ascii.stl")]);
  const s = await waitDone(page, 240_000);
  assert.equal(s.units, 3);
  assert.ok(s.unitDroplets.every((n) => n > 0), `every unit prints: ${s.unitDroplets}`);
  const mine = await downloadText(page);
  if (mine !== theirs) {
    const [a, b] = [mine.split("\n"), theirs.split("\n")];
    const i = a.findIndex((l, k) => l !== b[k]);
    assert.fail(`the page's .gco differs from the command line's at line ${i + 1}: ${JSON.stringify(a[i])} against ${JSON.stringify(b[i])}`);
  }
  assert.deepEqual(errors, []);
});

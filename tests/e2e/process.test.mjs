// The process engineer's tools in the page (issue 26): Orient per part (the core's candidates,
// one applied and undone), profiles (save, export, delete, import again; a bad file refused),
// the chamber's height in the 3D view, and the predicted density per unit against the CLI.
// Needs dist/ (scripts/build.sh) and target/release/dropslice.
import assert from "node:assert/strict";
import { execFileSync } from "node:child_process";
import { mkdtempSync, readFileSync, writeFileSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { after, before, test } from "node:test";
import { open3d, openPage, pick, repo, shared, start, stop, waitDone } from "./helpers.mjs";

const cli = join(repo, "target/release/dropslice");

let env;
const dir = mkdtempSync(join(tmpdir(), "dropslice-process-"));
before(async () => (env = await start()));
after(() => stop(env, dir));

/** The settings form's values, by name (text as typed, checkboxes as booleans). */
const formValues = (page) =>
  page.$$eval("#settings [name]", (els) => Object.fromEntries(els.map((e) => [e.name, e.type === "checkbox" ? e.checked : e.value])));

/** Types `value` into a setting (its group opened first, as a user would). */
async function setField(page, name, value) {
  await page.$eval(`#settings [name="${name}"]`, (el) => {
    for (let d = el.closest("details"); d; d = d.parentElement?.closest("details")) d.open = true;
  });
  await page.fill(`#settings [name="${name}"]`, String(value));
  await page.press(`#settings [name="${name}"]`, "Tab");
}

const rotation = (page) => page.evaluate(() => {
  const p = window.dropslice.job().parts[0];
  return [p.rotate_x, p.rotate_y, p.rotate_z];
});
const matrix = (page) => page.evaluate(() => Object.values(window.dropslice.view3d().matrices)[0]);

test("Orient lists candidates; applying the best turns the part in the 3D view; Ctrl+Z puts it back", async () => {
  const { page, errors } = await openPage(env.browser, env.url);
  await waitDone(page, 60_000);
  await pick(page, join(shared, "models/U_overhang.obj"));
  await waitDone(page, 60_000);
  await open3d(page);
  await page.waitForFunction(() => Object.keys(window.dropslice.view3d()?.matrices ?? {}).length === 1, null, { timeout: 30_000 });
  const rot0 = await rotation(page);
  const m0 = await matrix(page);

  await page.click("#part-orient");
  await page.waitForSelector("#orient-list .orient-pick", { timeout: 30_000 });
  const rows = await page.$$eval("#orient-list .orient-pick", (bs) => bs.map((b) => ({ text: b.textContent, current: b.getAttribute("aria-current") })));
  assert.ok(rows.length >= 2 && rows.length <= 5, `candidates shown: ${rows.length}`);
  for (const r of rows) assert.match(r.text, /[\d.]+ mm² unsupported · [\d.]+ mm high/);
  const areas = rows.map((r) => Number(/([\d.]+) mm² unsupported/.exec(r.text)[1]));
  assert.deepEqual([...areas].sort((a, b) => a - b), areas, "best first");
  // the U upside down: its current orientation leaves the most in the air, so it is not the best
  assert.equal(rows[0].current, "false", "the best is not the current orientation");
  assert.match(await page.locator("#orient-status").innerText(), /Now: [\d.]+ mm²; best: [\d.]+ mm²/);
  const [now, best] = (await page.locator("#orient-status").innerText()).match(/[\d.]+(?= mm²)/g).map(Number);
  assert.ok(best < now, `best ${best} mm² < now ${now} mm²`);

  await page.click('#orient-list .orient-pick[data-index="0"]');
  await page.waitForFunction((r) => JSON.stringify(window.dropslice.job().parts.map((p) => [p.rotate_x, p.rotate_y, p.rotate_z])[0]) !== JSON.stringify(r), rot0, { timeout: 30_000 });
  const rot1 = await rotation(page);
  assert.notDeepEqual(rot1, rot0);
  for (const [i, k] of ["x", "y", "z"].entries()) assert.equal(Number(await page.inputValue(`#part-rotate_${k}`)), rot1[i], `the rotate_${k} field`);
  await page.waitForFunction((m) => JSON.stringify(Object.values(window.dropslice.view3d().matrices)[0]) !== JSON.stringify(m), m0, { timeout: 30_000 });
  assert.equal(await page.getAttribute('#orient-list .orient-pick[data-index="0"]', "aria-current"), "true", "the applied one is marked current");
  assert.equal((await page.evaluate(() => window.dropslice.history())).undo, "orient");

  await page.locator("body").click({ position: { x: 5, y: 5 } });
  await page.keyboard.press("Control+z");
  await page.waitForFunction((r) => JSON.stringify(window.dropslice.job().parts.map((p) => [p.rotate_x, p.rotate_y, p.rotate_z])[0]) === JSON.stringify(r), rot0, { timeout: 30_000 });
  await page.waitForFunction((m) => JSON.stringify(Object.values(window.dropslice.view3d().matrices)[0]) === JSON.stringify(m), m0, { timeout: 30_000 });
  for (const [i, k] of ["x", "y", "z"].entries()) assert.equal(Number(await page.inputValue(`#part-rotate_${k}`)), rot0[i]);
  assert.deepEqual(errors, []);
  await page.context().close();
});

test("a profile saved, exported, deleted and imported again gives the same settings; a bad file changes nothing", async () => {
  const { page, errors } = await openPage(env.browser, env.url);
  page.on("dialog", (d) => void (d.type() === "prompt" ? d.accept("Chamber 180") : d.accept()));
  await waitDone(page, 60_000);
  await page.click("#profiles summary");
  await setField(page, "plate_z", 180);
  await setField(page, "plate_x", 140);
  await setField(page, "travel_speed", 75);
  const wanted = await formValues(page);
  assert.equal(wanted.plate_z, "180");

  await page.fill("#profile-name", "Test machine");
  await page.selectOption("#profile-kind", "machine");
  await page.click("#profile-save");
  await page.waitForSelector('#profile-list li[data-name="Test machine"]');
  const [download] = await Promise.all([page.waitForEvent("download"), page.click('#profile-list li[data-name="Test machine"] .profile-export')]);
  const file = join(dir, download.suggestedFilename());
  await download.saveAs(file);
  const json = JSON.parse(readFileSync(file, "utf8"));
  assert.equal(json.name, "Test machine");
  assert.equal(json.kind, "machine");
  assert.equal(json.settings.plate_z, 180);
  assert.equal(json.settings.travel_speed, 75);
  assert.ok(!("droplet_aspect" in json.settings), "a machine profile holds no material setting");

  await page.click('#profile-list li[data-name="Test machine"] .profile-delete');
  await page.waitForSelector('#profile-list li[data-name="Test machine"]', { state: "detached" });
  await page.click("#btn-reset");
  const reset = await formValues(page);
  assert.notEqual(reset.plate_z, "180");

  // a bad file: a material key in a machine profile; then one that is not JSON
  const bad = join(dir, "bad.json");
  writeFileSync(bad, JSON.stringify({ name: "Bad", kind: "machine", settings: { plate_z: 100, droplet_aspect: 1.2 } }));
  await page.setInputFiles("#profile-file", bad);
  await page.waitForFunction(() => document.getElementById("profile-status").classList.contains("bad"), null, { timeout: 30_000 });
  assert.match(await page.locator("#profile-status").innerText(), /bad\.json was not imported: .*droplet_aspect/);
  const junk = join(dir, "junk.json");
  writeFileSync(junk, "{not json");
  await page.setInputFiles("#profile-file", junk);
  await page.waitForFunction(() => /junk\.json was not imported/.test(document.getElementById("profile-status").textContent), null, { timeout: 30_000 });
  assert.equal(await page.locator("#profile-list li").count(), 0, "nothing was added");
  assert.deepEqual(await formValues(page), reset, "the settings did not change");

  // the bytes go to the core, which reads them as the CLI's --profile does: Latin-1 refused
  // saying what to do, a name of just U+FEFF refused, UTF-16 with its mark read (then deleted)
  const latin1 = join(dir, "latin1.json");
  writeFileSync(latin1, Buffer.from(JSON.stringify({ name: "Düsseldorf", kind: "machine", settings: {} }), "latin1"));
  await page.setInputFiles("#profile-file", latin1);
  await page.waitForFunction(() => /latin1\.json was not imported/.test(document.getElementById("profile-status").textContent), null, { timeout: 30_000 });
  assert.match(await page.locator("#profile-status").innerText(), /not UTF-8 .*save it as UTF-8/);
  const bom = join(dir, "bom.json");
  writeFileSync(bom, JSON.stringify({ name: "\ufeff", kind: "machine", settings: {} }));
  await page.setInputFiles("#profile-file", bom);
  await page.waitForFunction(() => /bom\.json was not imported/.test(document.getElementById("profile-status").textContent), null, { timeout: 30_000 });
  assert.match(await page.locator("#profile-status").innerText(), /visible characters/);
  const utf16 = join(dir, "utf16.json");
  writeFileSync(utf16, Buffer.concat([Buffer.from([0xff, 0xfe]), Buffer.from(JSON.stringify({ name: "Düsseldorf", kind: "machine", settings: { plate_z: 150 } }), "utf16le")]));
  await page.setInputFiles("#profile-file", utf16);
  await page.waitForSelector('#profile-list li[data-name="Düsseldorf"]', { timeout: 30_000 });
  await page.click('#profile-list li[data-name="Düsseldorf"] .profile-delete');
  await page.waitForSelector('#profile-list li[data-name="Düsseldorf"]', { state: "detached" });

  await page.setInputFiles("#profile-file", file);
  await page.waitForSelector('#profile-list li[data-name="Test machine"]', { timeout: 30_000 });
  assert.deepEqual(await formValues(page), reset, "importing does not apply");
  await page.click('#profile-list li[data-name="Test machine"] .profile-use');
  assert.deepEqual(await formValues(page), wanted);
  assert.equal((await page.evaluate(() => window.dropslice.history())).undo, "use profile Test machine");

  // renamed (a prompt), then kept across a reload, and a corrupt entry beside it ignored
  await page.click('#profile-list li[data-name="Test machine"] .profile-rename');
  await page.waitForSelector('#profile-list li[data-name="Chamber 180"]');
  await page.evaluate(() => {
    const list = JSON.parse(localStorage.getItem("dropslice.profiles.v1"));
    list.push({ name: "Corrupt", kind: "machine", settings: { plate_z: "tall" } }, 42);
    localStorage.setItem("dropslice.profiles.v1", JSON.stringify(list));
  });
  await page.reload();
  await waitDone(page, 60_000);
  assert.deepEqual(await page.$$eval("#profile-list li", (lis) => lis.map((li) => li.dataset.name)), ["Chamber 180"]);
  assert.deepEqual(errors, []);
  await page.context().close();
});

test("the 3D view draws the chamber's height", async () => {
  const { page, errors } = await openPage(env.browser, env.url);
  await waitDone(page, 60_000);
  await open3d(page);
  const z0 = await page.evaluate(() => window.dropslice.view3d().chamber);
  assert.ok(z0 > 0, `chamber ${z0}`);
  await setField(page, "plate_z", 120);
  await page.waitForFunction(() => window.dropslice.view3d().chamber === 120, null, { timeout: 10_000 });
  assert.deepEqual(errors, []);
  await page.context().close();
});

test("the predicted density per unit in the statistics is the command line's", async () => {
  // a two-material job: the cube in unit 0 and again in unit 1 (B₁ = 1.5 H)
  const job = { settings: { part_spacing: 5, unit1_droplet_aspect: 1.5 }, parts: [{ file: "cube.stl" }, { file: "cube.stl", unit: 1 }] };
  const jobFile = join(dir, "two-units.json");
  const cubeFile = join(dir, "cube.stl");
  writeFileSync(jobFile, JSON.stringify(job));
  writeFileSync(cubeFile, readFileSync(join(shared, "models/cube_20mm_ascii.stl")));
  const report = join(dir, "two-units.report.json");
  execFileSync(cli, [jobFile, "-o", join(dir, "two-units.gco"), "--report", report, "-q"]);
  const part = JSON.parse(readFileSync(report, "utf8")).part;
  const expected = [`${part.predicted_density.toFixed(1)} %`, `${part.units[1].predicted_density.toFixed(1)} %`];

  const { page, errors } = await openPage(env.browser, env.url);
  await waitDone(page, 60_000);
  assert.equal(await page.locator("#stat-density").innerText(), "–", "no density without the 3D analysis");
  assert.equal(await page.isVisible("#stat-density1"), false, "no unit-1 row in a job without unit-1 parts");
  await pick(page, [jobFile, cubeFile]);
  await waitDone(page, 60_000);
  await page.check("#opt-voids");
  await page.waitForFunction(() => {
    const st = window.dropslice.status();
    return st.state === "done" && st.analysed === st.layers;
  }, null, { timeout: 120_000, polling: 100 });
  const shown = () => page.evaluate(() => ["stat-density", "stat-density1"].map((id) => document.getElementById(id).textContent));
  await page.waitForFunction((want) => ["stat-density", "stat-density1"].every((id, k) => document.getElementById(id).textContent === want[k]), expected, { timeout: 10_000 })
    .catch(async () => assert.fail(`the page shows ${JSON.stringify(await shown())}, the command line ${JSON.stringify(expected)}`));
  assert.equal(await page.isVisible("#stat-density1-label"), true);
  assert.match(await page.getAttribute("#stat-density", "title"), /not a measured density/);
  assert.deepEqual(errors, []);
  await page.close();
});

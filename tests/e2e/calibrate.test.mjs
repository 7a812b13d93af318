// The droplet calibration panel (views/calibrate.ts) in headless Chromium: a slice's and an
// opened .gco's droplet count with a mass typed here give the suggestion of docs/spec.md's formula,
// computed in this test (V = m / (N ρ) · 1000 mm³, filling V / (B² H), aspect √(V/H) / H);
// "Use" puts it into the form; impossible and malformed inputs give messages, never a crash.
// Needs dist/ (scripts/build.sh) and target/release/dropslice.
import { after, before, test } from "node:test";
import assert from "node:assert/strict";
import { execFileSync } from "node:child_process";
import { mkdtempSync, readFileSync, writeFileSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { pick, repo, shared, startWithPage, status, stop, waitDone } from "./helpers.mjs";

let env;
let main;
const tmp = mkdtempSync(join(tmpdir(), "dropslice-calib-"));
const cli = join(repo, "target/release/dropslice");

before(async () => ({ env, main } = await startWithPage()));

after(() => stop(env, tmp));

/** docs/spec.md's figures for N droplets of a code with layer height h and aspect a, mass m (g)
 *  and density rho (g/cm³). */
function expected(n, h, a, m, rho) {
  const v = (m / (n * rho)) * 1000;
  const b = a * h;
  return { v, cell: b * b * h, filling: v / (b * b * h), aspect: Math.sqrt(v / h) / h };
}

/** A mass (as typed, 4 decimals) that makes the droplets of a code with layer height h fill
 *  cells of aspect `target`. */
function massFor(n, h, target, rho) {
  const b = target * h;
  return ((n * b * b * h * rho) / 1000).toFixed(4);
}

/** Waits until the panel has answered its last input (a result or a message). */
async function settled(page) {
  await page.waitForFunction(() => document.getElementById("calib").dataset.state !== "pending", null, { timeout: 30_000 });
  return page.getAttribute("#calib", "data-state");
}

/** Types the mass and waits for the panel's answer. */
async function typeMass(page, mass) {
  await page.fill("#calib-mass", mass);
  return settled(page);
}

async function shown(page) {
  const text = (id) => page.locator(`#${id}`).innerText();
  return {
    droplets: `${await text("calib-droplets-label")}: ${await text("calib-droplets")}`,
    now: await text("calib-now"),
    volume: await text("calib-volume"),
    cell: await text("calib-cell"),
    filling: await text("calib-filling"),
    aspect: await text("calib-aspect"),
    explanation: await text("calib-explanation"),
    use: await text("calib-use"),
  };
}

function checkShown(got, want, note) {
  assert.equal(got.volume, `${want.v.toFixed(5)} mm³`, note);
  assert.equal(got.cell, `${want.cell.toFixed(5)} mm³`, note);
  assert.equal(got.filling, `${(100 * want.filling).toFixed(1)} %`, note);
  assert.equal(got.aspect, want.aspect.toFixed(3), note);
  assert.equal(got.use, `Use droplet_aspect = ${want.aspect.toFixed(3)}`, note);
  assert.match(got.explanation, new RegExp(`set droplet_aspect to ${want.aspect.toFixed(3).replace(".", "\\.")} `), note);
}

/** Sets a field of the settings form (its group opened first). */
async function setField(page, name, value) {
  await page.locator(`#set-${name}`).evaluate((e) => (e.closest("details").open = true));
  await page.fill(`#set-${name}`, value);
}

test("a slice: the mass gives SPEC's suggestion, Use puts it in the form", async () => {
  const { page, errors } = main;
  await waitDone(page);
  // slice the sample again with a density and an aspect of our own (the panel takes both)
  await setField(page, "material_density", "1.2");
  await setField(page, "droplet_aspect", "1");
  await page.click("#btn-slice");
  const s = await waitDone(page);
  const n = s.droplets;
  assert.ok(n > 10_000, `droplets ${n}`);
  assert.equal((await page.locator("#stat-droplets").innerText()).replace(/,/g, ""), String(n));

  await page.click("#calib > summary");
  assert.equal(await page.inputValue("#calib-density"), "1.2", "the slice's material_density");
  assert.match(await page.locator("#calib-source").innerText(), /This slice: [\d,]+ droplets, H 0\.2 mm, droplet_aspect 1\b/);
  // no mass yet: a hint, no figures
  assert.equal(await page.isVisible("#calib-result"), false);
  assert.match(await page.locator("#calib-message").innerText(), /Type the measured mass/);

  const mass = massFor(n, 0.2, 1.137, 1.2);
  assert.equal(await typeMass(page, mass), "result");
  const got = await shown(page);
  const want = expected(n, 0.2, 1.0, Number(mass), 1.2);
  assert.ok(Math.abs(want.aspect - 1.137) < 1e-4, `the mass chosen gives ${want.aspect}`);
  checkShown(got, want, `slice, mass ${mass}`);
  assert.equal(got.droplets, `Droplets N (slice): ${n.toLocaleString("en-US")}`);
  assert.equal(got.now, "1");

  // Use: the form's droplet_aspect, and the Slice button asks for a new slice
  await page.click("#calib-use");
  assert.equal(await page.inputValue("#set-droplet_aspect"), "1.137");
  assert.match(await page.locator("#settings-status").innerText(), /Settings changed/);
  assert.match(await page.locator("#calib-message").innerText(), /droplet_aspect is now 1\.137.*Slice/);

  // a density typed instead of the slice's: ρ twice as large halves V, aspect / √2
  await page.fill("#calib-density", "2.4");
  assert.equal(await settled(page), "result");
  checkShown(await shown(page), expected(n, 0.2, 1.0, Number(mass), 2.4), "density 2.4");
  await page.fill("#calib-density", "1.2");

  // impossible: 1000 kg; not a number; zero; a density out of range
  assert.equal(await typeMass(page, "1000000"), "refused");
  assert.match(await page.locator("#calib-message").innerText(), /^impossible: check the mass, the density/);
  assert.equal(await page.isVisible("#calib-result"), false);
  assert.equal(await page.isVisible("#calib-use"), false);
  await typeMass(page, "12 g");
  assert.match(await page.locator("#calib-message").innerText(), /mass must be a number of grams greater than 0/);
  assert.equal(await page.getAttribute("#calib-mass", "aria-invalid"), "true");
  await typeMass(page, "0");
  assert.match(await page.locator("#calib-message").innerText(), /greater than 0/);
  await page.fill("#calib-density", "50");
  assert.equal(await typeMass(page, mass), "refused");
  assert.match(await page.locator("#calib-message").innerText(), /the density must be greater than 0 and at most/);
  // back to a good density: the figures again
  await page.fill("#calib-density", "1.2");
  assert.equal(await settled(page), "result");
  checkShown(await shown(page), want, "again");
  assert.equal((await status(page)).state, "done");
  assert.deepEqual(errors, []);
});

test("an opened .gco: its header's count, H, aspect and density; or its commands' count", async () => {
  const { page, errors } = main;
  const gco = join(tmp, "screw.gco");
  execFileSync(cli, [join(shared, "models/M3x10_screw.stl"), "-o", gco, "-q", "--set", "layer_height=0.25", "--set", "droplet_aspect=1.1", "--set", "material_density=1.25"], {
    stdio: "inherit",
  });
  const text = readFileSync(gco, "utf8");
  const n = Number(/^; droplets total\s*=\s*(\d+)/m.exec(text)[1]);
  assert.ok(n > 1000, `header total ${n}`);

  await pick(page, gco);
  const s = await waitDone(page);
  assert.equal(s.name, "screw.gco");
  assert.equal(s.droplets, n, "the page read as many droplets as the header says");
  await page.waitForFunction(() => document.getElementById("calib-source").innerText.startsWith("screw.gco"));
  assert.match(await page.locator("#calib-source").innerText(), /H 0\.25 mm, droplet_aspect 1\.1/);
  assert.equal(await page.inputValue("#calib-density"), "1.25", "the header's material_density");

  const mass = massFor(n, 0.25, 1.07, 1.25);
  assert.equal(await typeMass(page, mass), "result");
  const got = await shown(page);
  checkShown(got, expected(n, 0.25, 1.1, Number(mass), 1.25), `.gco, mass ${mass}`);
  assert.equal(got.droplets, `Droplets N (header): ${n.toLocaleString("en-US")}`);
  assert.equal(got.now, "1.1");
  // the file is still the page's after other work: a different mass, a new answer
  await typeMass(page, "1000000");
  assert.match(await page.locator("#calib-message").innerText(), /^impossible/);

  // the same code without the header's total: counted from its commands, said so
  const bare = join(tmp, "bare.gco");
  writeFileSync(bare, text.replace(/^; droplets total.*\n/m, ""));
  await pick(page, bare);
  await waitDone(page);
  await page.waitForFunction(() => document.getElementById("calib-source").innerText.startsWith("bare.gco"));
  assert.equal(await typeMass(page, mass), "result");
  const counted = await shown(page);
  checkShown(counted, expected(n, 0.25, 1.1, Number(mass), 1.25), "bare .gco");
  assert.equal(counted.droplets, `Droplets N (counted): ${n.toLocaleString("en-US")}`);
  assert.match(counted.explanation, /counted from the code/);

  // a code that sets no droplet: the core's message
  const empty = join(tmp, "empty.gco");
  const header = text.slice(0, text.search(/^[GM]\d/m));
  writeFileSync(empty, `${header.replace(/^; droplets total.*\n/m, "")}G01 X1 Y1 Z0.25\n`);
  await pick(page, empty);
  await waitDone(page);
  await page.waitForFunction(() => document.getElementById("calib-source").innerText.startsWith("empty.gco"));
  assert.equal(await typeMass(page, "1"), "refused");
  assert.match(await page.locator("#calib-message").innerText(), /no droplet count in its header and sets no droplets/);
  assert.deepEqual(errors, []);
});

// Orient can be cancelled (issue 39, "The user's work survives"): the selected part's Orient
// shows Cancel while the core compares orientations; Cancel stops the job worker's long call
// (that worker is replaced, the others keep the slice), the part keeps its rotation, and a
// later Orient, a slice and a download work. Needs dist/ (scripts/build.sh).
import assert from "node:assert/strict";
import { mkdtempSync, writeFileSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { after, before, test } from "node:test";
import { downloadText, openPage, pick, shared, start, status, stop, torusStl, waitDone } from "./helpers.mjs";

let env;
const dir = mkdtempSync(join(tmpdir(), "dropslice-orient-"));
before(async () => (env = await start()));
after(() => stop(env, dir));

const rotation = (page) =>
  page.evaluate(() => {
    const p = window.dropslice.job().parts[0];
    return [p.rotate_x, p.rotate_y, p.rotate_z];
  });
const orientState = (page) => page.getAttribute("#orient-box", "data-state");

/** Waits for the Orient box to reach `state`. */
const orientReaches = (page, state, timeout = 60_000) =>
  page.waitForFunction((s) => document.getElementById("orient-box").dataset.state === s, state, { timeout, polling: 50 });

/** Orient again: candidates listed, the best first. */
async function orientWorks(page) {
  await page.click("#part-orient");
  await orientReaches(page, "done", 120_000);
  const rows = await page.$$eval("#orient-list .orient-pick", (bs) => bs.map((b) => b.textContent));
  assert.ok(rows.length >= 2, `candidates listed: ${rows.length}`);
  for (const r of rows) assert.match(r, /[\d.]+ mm² unsupported · [\d.]+ mm high/);
  assert.equal(await page.isHidden("#orient-cancel"), true, "no Cancel once answered");
}

test("Orient cancelled at once: the part unchanged, only the job worker replaced; Orient, slicing and the download work after", async () => {
  const { page, errors } = await openPage(env.browser, `${env.url}?workers=2`);
  await waitDone(page, 60_000);
  await pick(page, join(shared, "models/U_overhang.obj"));
  await waitDone(page, 60_000);
  const rot0 = await rotation(page);
  const history0 = await page.evaluate(() => window.dropslice.history());
  const started0 = (await status(page)).workersStarted;
  assert.equal(await page.isHidden("#orient-cancel"), true, "no Cancel before Orient");

  // Cancel in the same task as Orient: the request is made and stopped before any answer.
  await page.evaluate(() => {
    document.getElementById("part-orient").click();
    const cancel = document.getElementById("orient-cancel");
    if (cancel.hidden) throw new Error("no Cancel button while Orient runs");
    cancel.click();
  });
  await orientReaches(page, "cancelled");
  assert.match(await page.locator("#orient-status").innerText(), /Cancelled: the part is as it was/);
  assert.equal(await page.isHidden("#orient-cancel"), true);
  assert.equal(await page.locator("#orient-list .orient-pick").count(), 0, "no candidates from the cancelled run");
  assert.deepEqual(await rotation(page), rot0, "the part keeps its rotation");
  assert.deepEqual(await page.evaluate(() => window.dropslice.history()), history0, "nothing recorded");
  assert.equal((await status(page)).workersStarted, started0 + 1, "the job worker alone was replaced");
  assert.equal(await page.isHidden("#banner"), true, "no error shown");

  // The page goes on: Orient lists candidates, the finished slice downloads, a new slice runs.
  await orientWorks(page);
  assert.match(await downloadText(page), /G25|G26/);
  await page.evaluate(() => (document.body.dataset.state = "picking"));
  await page.click("#btn-slice");
  await waitDone(page, 60_000);
  assert.deepEqual(errors, []);
  await page.context().close();
});

test("with one worker, the finished slice's model is opened again after a cancelled Orient", async () => {
  const { page, errors } = await openPage(env.browser, `${env.url}?workers=1`);
  await waitDone(page, 60_000);
  await pick(page, join(shared, "models/U_overhang.obj"));
  await waitDone(page, 60_000);
  assert.equal((await status(page)).workers, 1);
  const rot0 = await rotation(page);
  await page.evaluate(() => {
    document.getElementById("part-orient").click();
    document.getElementById("orient-cancel").click();
  });
  await orientReaches(page, "cancelled");
  assert.deepEqual(await rotation(page), rot0);
  // The download needs a worker holding the slice's model: the fresh job worker has it again.
  assert.match(await downloadText(page), /G25|G26/);
  await orientWorks(page);
  assert.deepEqual(errors, []);
  await page.context().close();
});

test("Orient of a part of a million facets cancelled while the core compares: the part unchanged, a later Orient answers", async () => {
  const { page, errors } = await openPage(env.browser, `${env.url}?workers=2`);
  await waitDone(page, 60_000);
  const torus = join(dir, "torus1m.stl");
  writeFileSync(torus, torusStl(1000, 500));
  await pick(page, torus);
  await waitDone(page, 240_000);
  const rot0 = await rotation(page);
  const started0 = (await status(page)).workersStarted;
  assert.equal((await status(page)).jobWorkerLoad, 0, "the job worker is idle");
  await page.click("#part-orient");
  // The request is with the job worker (its one pending request): it is in the core's call.
  await page.waitForFunction(() => window.dropslice.status().jobWorkerLoad > 0, null, { polling: 10 });
  await page.click("#orient-cancel");
  await orientReaches(page, "cancelled");
  assert.deepEqual(await rotation(page), rot0);
  assert.equal((await status(page)).workersStarted, started0 + 1);
  assert.equal((await status(page)).jobWorkerLoad, 0, "the fresh job worker owes nothing");
  await orientWorks(page);
  assert.deepEqual(errors, []);
  await page.context().close();
});

// The user's work survives (www/core/jobstore.ts, www/flows/persist.ts, flows/history.ts,
// core/profiles.ts): the job kept in the browser's IndexedDB comes back after a reload (after
// an Undo too) and after a crash, with a notice whose Start over gives the sample with the
// defaults; a preview link's job becomes the visitor's at the first edit (the address drops
// the link); leaving asks while the job is not kept; a damaged store is set aside with a word;
// a job over the cap is said not to be kept; undo snapshots keep no display meshes; a 201st
// profile is refused. As a user, through the DOM.
import { after, before, test } from "node:test";
import assert from "node:assert/strict";
import { boxStl, cube, openPage, pick, shareLink, start, stop, torusStl, waitDone, waitSettled } from "./helpers.mjs";

let env;
before(async () => (env = await start()));
after(() => stop(env));

const job = (page) => page.evaluate(() => window.dropslice.job());
const persist = (page) => page.evaluate(() => window.dropslice.persist());
const box = (name, a, b, c) => ({ name, mimeType: "model/stl", buffer: boxStl(a, b, c) });
const cubeFile = { name: "cube_20mm_ascii.stl", mimeType: "model/stl", buffer: cube };
/** The parts' specs as a user sees them (ids and meshes aside). */
const specs = (j) => j.parts.map(({ id, mesh, ...spec }) => spec);

/** The number of models' bytes kept in the browser's IndexedDB. */
const storedModels = (page) =>
  page.evaluate(
    () =>
      new Promise((ok, fail) => {
        const r = indexedDB.open("dropslice.job");
        r.onerror = () => fail(r.error);
        r.onsuccess = () => {
          const count = r.result.transaction("models").objectStore("models").count();
          count.onsuccess = () => {
            r.result.close();
            ok(count.result);
          };
        };
      }),
  );

/** A new page (its own browser context; `query` added to the address) once its first slice is
 *  done: the sample's, or the kept job's. openPage()'s { page, context, errors }. */
async function sliced(query = "") {
  const opened = await openPage(env.browser, env.url + query);
  await waitDone(opened.page, 60_000);
  return opened;
}

/** Waits until the job on screen is the one kept in the browser. */
const kept = (page) => page.waitForFunction(() => window.dropslice.persist().state === "saved", null, { timeout: 30_000 });

/** Types `value` into the selected part's field `key` (rotate_z, copies, …) and waits until the
 *  core took it. */
async function editPart(page, index, key, value) {
  await page.click(`.part-item:nth-child(${index + 1})`);
  await page.fill(`#part-${key}`, String(value));
  await page.press(`#part-${key}`, "Enter");
  await page.waitForFunction(([i, k, v]) => window.dropslice.job().parts[i][k] === v, [index, key, value]);
}

/** Closes `page` running its beforeunload: whether the browser asked first. The question is
 *  answered "stay" (the page is left open), or "leave" with `leave` (a context closed with a
 *  page that would ask takes the browser down with it). */
async function asksOnLeaving(page, leave = false) {
  const asked = new Promise((ok) => {
    page.once("dialog", async (d) => {
      ok(d.type());
      await (leave ? d.accept() : d.dismiss());
    });
    page.once("close", () => ok(null));
  });
  await page.close({ runBeforeUnload: true });
  const type = await asked;
  return type === "beforeunload";
}

test("two models, one rotated, a third opened over them, Undo, reload: the job is back with the notice; Start over gives the sample with the defaults", async () => {
  const { page, errors, context } = await sliced();
  assert.match((await job(page)).name, /sample/);
  await page.locator("#set-layer_height").evaluate((e) => (e.closest("details").open = true));
  await page.fill("#set-layer_height", "0.15");
  await pick(page, [cubeFile, box("slab.stl", 30, 20, 4)]);
  await waitDone(page);
  await editPart(page, 1, "rotate_z", 30);
  const two = await job(page);
  await pick(page, [box("third.stl", 10, 10, 10)]);
  await waitDone(page);
  assert.equal((await job(page)).name, "third.stl");
  await page.click("#btn-undo");
  await page.waitForFunction(() => window.dropslice.job().parts.length === 2);
  assert.deepEqual(specs(await job(page)), specs(two));
  await kept(page);
  // each model's bytes once (by SHA-256), whatever the edits; the third file's are gone
  assert.equal(await storedModels(page), 2);
  await page.reload();
  await waitDone(page, 60_000);
  const back = await job(page);
  assert.deepEqual(specs(back), specs(two), "the two models, the rotation");
  assert.equal(back.parts[1].rotate_z, 30);
  assert.equal(await page.inputValue("#set-layer_height"), "0.15", "the settings with it");
  assert.equal(await page.isVisible("#persist-note"), true);
  assert.match(await page.locator("#persist-note").innerText(), /Your job from last time was restored/);
  assert.equal(await page.isVisible("#persist-start-over"), true);
  // Start over: the sample, every setting at its default; the job is forgotten
  await page.evaluate(() => (document.body.dataset.state = "picking"));
  await page.click("#persist-start-over");
  await waitDone(page, 60_000);
  assert.match((await job(page)).name, /sample/);
  assert.equal(await page.inputValue("#set-layer_height"), "0.2");
  assert.equal(await page.isVisible("#persist-note"), false);
  // Undo brings the restored job back (Start over is one change)
  assert.match((await page.evaluate(() => window.dropslice.history())).undo, /open the sample part/);
  await kept(page);
  await page.reload();
  await waitDone(page, 60_000);
  assert.match((await job(page)).name, /sample/, "what is kept now is the sample");
  assert.equal(await page.inputValue("#set-layer_height"), "0.2");
  assert.deepEqual(errors, []);
  await context.close();
});

test("leaving asks while the job is not kept: after an edit and after an Undo; not once it is kept", async () => {
  const { page, errors, context } = await sliced();
  await kept(page);
  // the writes held: each change stays pending
  await page.evaluate(() => window.dropslice.persistPause(true));
  await editPart(page, 0, "rotate_z", 45);
  assert.equal((await persist(page)).state, "pending");
  assert.equal(await asksOnLeaving(page), true, "asked after an edit");
  await page.click("#btn-undo");
  await page.waitForFunction(() => window.dropslice.job().parts[0].rotate_z === 0);
  assert.equal(await asksOnLeaving(page), true, "asked after an Undo");
  // released: once the job is kept, leaving loses nothing and asks nothing
  await page.evaluate(() => window.dropslice.persistPause(false));
  await kept(page);
  assert.equal(await asksOnLeaving(page), false);
  assert.equal(page.isClosed(), true);
  assert.deepEqual(errors, []);
  await context.close();
});

test("a crash loses nothing: the page that crashed after an edit comes back with the edited job", async () => {
  const { page, errors, context } = await sliced();
  await pick(page, [cubeFile]);
  await waitDone(page);
  await editPart(page, 0, "rotate_z", 15);
  await kept(page);
  // the renderer dies: no pagehide, no beforeunload
  const crashed = new Promise((ok) => page.once("crash", ok));
  const cdp = await context.newCDPSession(page);
  cdp.send("Page.crash").catch(() => {});
  await crashed;
  const again = await context.newPage();
  again.on("pageerror", (e) => errors.push(String(e)));
  await again.goto(env.url);
  await waitDone(again, 60_000);
  const j = await job(again);
  assert.equal(j.name, "cube_20mm_ascii.stl");
  assert.equal(j.parts[0].rotate_z, 15);
  assert.match(await again.locator("#persist-note").innerText(), /Your job from last time was restored/);
  assert.deepEqual(errors, []);
  await context.close();
});

test("a kept job that no longer fits the plate comes back as it was left, with the banner", async () => {
  const { page, errors, context } = await sliced();
  await pick(page, [box("a.stl", 60, 60, 5), box("b.stl", 60, 60, 5)]);
  await waitDone(page);
  // a plate narrower than the parts: the job stays as it was, the banner says so
  await page.locator("#set-plate_x").evaluate((e) => (e.closest("details").open = true));
  await page.fill("#set-plate_x", "50");
  // the plate rule (docs/jobs.md): each part larger than the plate is named, with what fits
  const misfit = () => /larger than the plate/.test(document.getElementById("parts-warnings").innerText);
  await page.waitForFunction(misfit);
  await page.waitForTimeout(500);
  await kept(page);
  await page.reload();
  await waitSettled(page, 60_000);
  assert.equal(await page.inputValue("#set-plate_x"), "50");
  const j = await job(page);
  assert.deepEqual(j.parts.map((p) => p.file), ["a.stl", "b.stl"], "the job as it was left");
  await page.waitForFunction(misfit, null, { timeout: 30_000 });
  assert.equal(await page.locator("#btn-download").isEnabled(), false, "not sliced: the parts do not fit");
  assert.match(await page.locator("#persist-note").innerText(), /Your job from last time was restored/);
  assert.deepEqual(errors, []);
  await context.close();
});

test("a job over the cap is said not to be kept, and leaving asks", async () => {
  const { page, errors, context } = await sliced("?jobcap=0");
  await page.waitForFunction(() => window.dropslice.persist().state === "over");
  assert.match(await page.locator("#persist-note").innerText(), /more than the 0 MB the page keeps in the browser: it will not come back after a reload/);
  await editPart(page, 0, "rotate_z", 10);
  assert.equal(await asksOnLeaving(page, true), true);
  assert.deepEqual(errors, []);
  await context.close();
});

test("a link page becomes the visitor's own at the first edit: the address drops the link, a reload brings back the edited job", async () => {
  // the link: the cube at scale 1.2 with 2 contours
  const made = await sliced();
  await pick(made.page, [cubeFile]);
  await waitDone(made.page);
  await editPart(made.page, 0, "scale_x", 1.2);
  await made.page.locator("#set-contours").evaluate((e) => (e.closest("details").open = true));
  await made.page.fill("#set-contours", "3");
  await made.page.evaluate(() => (document.body.dataset.state = "picking"));
  await made.page.click("#btn-slice");
  await waitDone(made.page);
  const url = await shareLink(made.page);
  await made.context.close();

  const { page, errors, context } = await sliced();
  // the visitor's own job, kept
  await pick(page, [box("own.stl", 12, 12, 6)]);
  await waitDone(page);
  await kept(page);
  // a link opened and left without an edit: the visitor's job is still theirs
  await page.goto("about:blank");
  await page.goto(url);
  await waitDone(page, 60_000);
  assert.equal((await job(page)).name, "cube_20mm_ascii.stl");
  assert.equal((await persist(page)).link, true);
  assert.equal(await page.inputValue("#set-contours"), "3");
  await page.goto("about:blank");
  await page.goto(env.url);
  await waitDone(page, 60_000);
  assert.equal((await job(page)).name, "own.stl", "the link did not replace the visitor's job");
  // the link again, and an edit: contours 3 → 2, scale 1.2 → 1
  await page.goto("about:blank");
  await page.goto(url);
  await waitDone(page, 60_000);
  assert.ok(new URL(page.url()).hash.length > 1);
  await page.locator("#set-contours").evaluate((e) => (e.closest("details").open = true));
  await page.fill("#set-contours", "2");
  await page.waitForFunction(() => location.hash === "");
  assert.match(await page.locator("#persist-note").innerText(), /opened from a preview link; with your edit its job and settings are now yours, kept in this browser/);
  await editPart(page, 0, "scale_x", 1);
  await kept(page);
  await page.reload();
  await waitDone(page, 60_000);
  assert.equal(new URL(page.url()).hash, "");
  const j = await job(page);
  assert.equal(j.name, "cube_20mm_ascii.stl", "the edited job, not the visitor's old one");
  assert.equal(j.parts[0].scale_x, 1);
  assert.equal(await page.inputValue("#set-contours"), "2");
  // Copy preview link makes a new link of the edited job
  const again = await shareLink(page);
  assert.notEqual(again, url);
  assert.ok(new URL(again).hash.length > 1);
  assert.equal(new URL(page.url()).hash, "", "the address stays the page's");
  assert.deepEqual(errors, []);
  await context.close();
});

test("a damaged store is set aside with a word: the sample is shown", async () => {
  const { page, errors, context } = await sliced();
  await kept(page);
  /** Changes the kept job with `change(record, models)` (its source run in the page), then
   *  reloads. The source goes into the evaluated text: the page's CSP refuses eval. */
  const tamper = async (change) => {
    await page.evaluate(`new Promise((ok, fail) => {
      const r = indexedDB.open("dropslice.job");
      r.onerror = () => fail(r.error);
      r.onsuccess = () => {
        const db = r.result;
        const tx = db.transaction(["job", "models"], "readwrite");
        const get = tx.objectStore("job").get("current");
        get.onsuccess = () => {
          const rec = get.result;
          (${change})(rec, tx.objectStore("models"));
          tx.objectStore("job").put(rec, "current");
        };
        tx.oncomplete = () => { db.close(); ok(); };
        tx.onerror = () => fail(tx.error);
      };
    })`);
    await page.reload();
    await waitDone(page, 60_000);
  };
  await tamper("(rec) => { rec.parts[0].scale_x = -5; }");
  assert.match((await job(page)).name, /sample/);
  assert.match(await page.locator("#persist-note").innerText(), /The job kept from last time could not be read \(its part 1's scale_x is not a number in the core's range\): it was set aside/);
  assert.equal(await page.isVisible("#persist-start-over"), false);
  // bytes that are not the model's
  await kept(page);
  await tamper("(rec, models) => { models.put(new Blob([new Uint8Array(rec.files[0].bytes)]), rec.files[0].sha256); }");
  assert.match(await page.locator("#persist-note").innerText(), /the bytes of “sample[^”]*” do not match their SHA-256/);
  // not a job at all
  await kept(page);
  await tamper("(rec) => { rec.version = 'x'; rec.files = 42; }");
  assert.match(await page.locator("#persist-note").innerText(), /could not be read \(it is not a job of this page\)/);
  assert.match((await job(page)).name, /sample/);
  assert.deepEqual(errors, []);
  await context.close();
});

test("undo snapshots keep no display meshes: 14 edits of the copies of a 600,000-facet part", async () => {
  const { page, errors, context } = await sliced();
  await pick(page, [{ name: "torus.stl", mimeType: "model/stl", buffer: torusStl(1000, 300, 15, 5) }]);
  await waitDone(page);
  await page.click("#mode-3d");
  await page.waitForFunction(() => window.dropslice.job().parts[0].mesh > 0, null, { timeout: 60_000 });
  // 1 copy: the whole budget (300,000 triangles; about 220,000 drawn), 3 copies: a third (about
  // 80,000): each change fetches the mesh of the new share again
  const N = 14;
  for (let i = 0; i < N; i++) {
    const copies = i % 2 === 0 ? 3 : 1;
    await editPart(page, 0, "copies", copies);
    await page.waitForFunction((c) => {
      const p = window.dropslice.job().parts[0];
      return c === 3 ? p.mesh > 0 && p.mesh <= 100_000 : p.mesh > 100_000;
    }, copies, { timeout: 60_000 });
  }
  const h = await page.evaluate(() => window.dropslice.historyBytes());
  assert.ok(h.snapshots > N, `${h.snapshots} snapshots`);
  // the meshes are 8 and 3 MB: the snapshots keep none beyond the job's own
  assert.equal(h.bytes, 0, `${h.bytes} bytes kept by the snapshots alone`);
  // and the page's heap did not grow by a mesh an edit (14 × 5.5 MB were kept before: about 110 MB, against 35 MB now)
  const cdp = await context.newCDPSession(page);
  await cdp.send("HeapProfiler.collectGarbage");
  const usage = await cdp.send("Runtime.getHeapUsage");
  const held = usage.usedSize + (usage.backingStorageSize ?? 0);
  assert.ok(held < 75 * 2 ** 20, `heap and array buffers: ${Math.round(held / 2 ** 20)} MB`);
  assert.deepEqual(errors, []);
  await context.close();
});

test("the 201st profile is refused with a message; replacing one of the 200 is not", async () => {
  const { page, errors, context } = await sliced();
  await page.evaluate(() => {
    const list = Array.from({ length: 200 }, (_, i) => ({ name: `P${i}`, kind: "machine", settings: { plate_z: 100 + i } }));
    localStorage.setItem("dropslice.profiles.v1", JSON.stringify(list));
  });
  await page.reload();
  await waitDone(page, 60_000);
  await page.click("#profiles summary");
  assert.equal(await page.locator("#profile-list li").count(), 200);
  await page.fill("#profile-name", "One more");
  await page.click("#profile-save");
  assert.match(await page.locator("#profile-status").innerText(), /“One more” was not saved\. There are 200 profiles, the most the page keeps: delete one/);
  assert.equal(await page.locator("#profile-status").getAttribute("class"), "hint bad");
  assert.equal(await page.locator("#profile-list li").count(), 200);
  assert.equal(await page.evaluate(() => JSON.parse(localStorage.getItem("dropslice.profiles.v1")).length), 200);
  assert.equal(await page.locator('#profile-list li[data-name="One more"]').count(), 0);
  // the same name as one of them replaces it
  await page.fill("#profile-name", "P7");
  await page.click("#profile-save");
  assert.match(await page.locator("#profile-status").innerText(), /Replaced the machine profile “P7”/);
  // after a deletion there is room again
  page.once("dialog", (d) => d.accept());
  await page.click('#profile-list li[data-name="P0"] .profile-delete');
  await page.waitForSelector('#profile-list li[data-name="P0"]', { state: "detached" });
  await page.fill("#profile-name", "One more");
  await page.click("#profile-save");
  await page.waitForSelector('#profile-list li[data-name="One more"]');
  assert.deepEqual(errors, []);
  await context.close();
});

// The droplet estimate covers every unit and the support (issue 22): a preview link with
// support on and a tiny unit1_droplet_aspect (or a small droplet_aspect), or a job link with a
// unit-1 part and a tiny B₁, is refused when the job is built, before any layer is sliced. The
// banner names the setting to change, nothing panics, and the page keeps answering.
import { after, before, test } from "node:test";
import assert from "node:assert/strict";
import { createHash } from "node:crypto";
import { readFileSync } from "node:fs";
import { join } from "node:path";
import { deflateRawSync } from "node:zlib";
import { benchy, start, status } from "./helpers.mjs";

let env;
const cube = readFileSync(join(benchy, "../cube_20mm_ascii.stl"));
const cubeSha = createHash("sha256").update(cube).digest("hex");
const b64url = (buf) => Buffer.from(buf).toString("base64url");

before(async () => {
  env = await start();
});

after(async () => {
  await env?.close();
});

/** A preview link's fragment: the state deflated, the cube embedded. */
function link(state) {
  const full = { layer: 10, view: { scale: 12, cx: 1, cy: 2 }, name: "cube.stl", sha256: cubeSha, ...state };
  return `#p=${b64url(deflateRawSync(Buffer.from(JSON.stringify(full))))}&m=${b64url(deflateRawSync(cube))}`;
}

/** The page answers page.evaluate within 2 s. */
async function answers(page) {
  const answer = await Promise.race([page.evaluate(() => 1), new Promise((ok) => setTimeout(() => ok("timeout"), 2000))]);
  assert.equal(answer, 1, "the page did not answer within 2 s");
}

/** Waits until the page has settled (a slice done or failed), answering all the while. */
async function settle(page, timeout = 60_000) {
  const t0 = Date.now();
  for (;;) {
    await answers(page);
    const s = await status(page);
    if (["done", "error", "cancelled", "idle"].includes(s.state)) return s;
    if (Date.now() - t0 > timeout) assert.fail(`the page did not settle: ${JSON.stringify(s)}`);
    await page.waitForTimeout(100);
  }
}

// [what, link state, the banner must match all of these]
const CASES = [
  ["support on, unit1_droplet_aspect 1e-6", { settings: { support: "unit1", unit1_droplet_aspect: 1e-6 } }, [/support/, /unit1_droplet_aspect/, /droplets/]],
  ["support on, unit1_droplet_aspect 0.001", { settings: { support: "unit1", unit1_droplet_aspect: 0.001 } }, [/support/, /unit1_droplet_aspect/, /droplets/]],
  ["support on, droplet_aspect 0.025", { settings: { support: "unit1", droplet_aspect: 0.025 } }, [/droplet_aspect/, /unit 0/, /support = off/]],
  [
    "a job with a unit-1 part, unit1_droplet_aspect 1e-6",
    {
      settings: { unit1_droplet_aspect: 1e-6 },
      files: [{ name: "cube.stl", sha256: cubeSha, bytes: cube.length }],
      parts: [{ file: "cube.stl", unit: 1 }],
    },
    [/unit 1/, /unit1_droplet_aspect/, /droplets/],
  ],
];

for (const [what, state, expected] of CASES) {
  test(`refused at once: ${what}`, async () => {
    const context = await env.browser.newContext({ viewport: { width: 1280, height: 800 } });
    const page = await context.newPage();
    const errors = [];
    page.on("pageerror", (e) => errors.push(String(e)));
    page.on("console", (m) => {
      if (m.type() === "error") errors.push(m.text());
    });
    const t0 = Date.now();
    await page.goto(env.url + link(state));
    const s = await settle(page);
    const seconds = (Date.now() - t0) / 1000;
    console.log(`# ${what}: ${s.state} after ${seconds.toFixed(1)} s`);
    assert.equal(s.state, "error", JSON.stringify(s));
    assert.ok(await page.isVisible("#banner"), "a banner");
    const text = await page.locator("#banner").innerText();
    for (const re of expected) assert.match(text, re, `banner: ${text}`);
    assert.doesNotMatch(text, /panic|unreachable|capacity overflow|internal error|out of memory/i);
    assert.ok(seconds < 30, `${seconds} s`);
    // The page keeps answering, and slices a good job afterwards.
    for (let i = 0; i < 4; i++) {
      await answers(page);
      await page.waitForTimeout(150);
    }
    await page.goto(env.url + link({ settings: { support: "unit1" } }));
    await page.reload();
    const good = await settle(page);
    assert.equal(good.state, "done", JSON.stringify(good));
    assert.ok(good.droplets > 0);
    assert.deepEqual(errors, [], "page errors");
    await context.close();
  });
}

// The droplet estimate covers every unit and the support (issue 22): a preview link with
// support on and a tiny unit1_droplet_aspect (or a small droplet_aspect), or a job link with a
// unit-1 part and a tiny B₁, is refused when the job is built, before any layer is sliced. The
// banner names the setting to change, nothing panics, and the page keeps answering.
import { test } from "node:test";
import assert from "node:assert/strict";
import { deflateRawSync } from "node:zlib";
import { answers, b64url, cube, cubeSha, openPage, settleAnswering as settle, startForTests } from "./helpers.mjs";

const env = startForTests();

/** A preview link's fragment: the state deflated, the cube embedded. */
function link(state) {
  const full = { layer: 10, view: { scale: 12, cx: 1, cy: 2 }, name: "cube.stl", sha256: cubeSha, ...state };
  return `#p=${b64url(deflateRawSync(Buffer.from(JSON.stringify(full))))}&m=${b64url(deflateRawSync(cube))}`;
}

// [what, link state, the banner must match all of these]
const CASES = [
  ["support on, unit1_droplet_aspect 0.002", { settings: { support: "unit1", unit1_droplet_aspect: 0.002 } }, [/support/, /unit1_droplet_aspect/, /droplets/]],
  ["support on, unit1_droplet_aspect 0.001", { settings: { support: "unit1", unit1_droplet_aspect: 0.001 } }, [/support/, /unit1_droplet_aspect/, /droplets/]],
  ["support on, droplet_aspect 0.025", { settings: { support: "unit1", droplet_aspect: 0.025 } }, [/droplet_aspect/, /unit 0/, /support = off/]],
  [
    "a job with a unit-1 part, unit1_droplet_aspect 0.001",
    {
      settings: { unit1_droplet_aspect: 0.001 },
      files: [{ name: "cube.stl", sha256: cubeSha, bytes: cube.length }],
      parts: [{ file: "cube.stl", unit: 1 }],
    },
    [/unit 1/, /unit1_droplet_aspect/, /droplets/],
  ],
];

for (const [what, state, expected] of CASES) {
  test(`refused at once: ${what}`, async () => {
    const t0 = Date.now();
    const { page, context, errors } = await openPage(env.browser, env.url + link(state), { width: 1280, height: 800 });
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
    await answers(page, 4);
    await page.goto(env.url + link({ settings: { support: "unit1" } }));
    await page.reload();
    const good = await settle(page);
    assert.equal(good.state, "done", JSON.stringify(good));
    assert.ok(good.droplets > 0);
    assert.deepEqual(errors, [], "page errors");
    await context.close();
  });
}

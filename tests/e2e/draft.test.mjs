// The preparation off the critical path (docs/page.md): on two workers the other worker slices
// from the job worker's draft while the job is prepared. Whether the draft stands (3DBenchy:
// confirmed, `confirm_job`) or not (3DBenchy inside out: its shell is turned, so the other
// worker is replaced and takes the prepared job, `adopt_job`), the downloaded .gco is the CLI's.
// Needs dist/ (scripts/build.sh) and target/release/dropslice.
import { after, test } from "node:test";
import assert from "node:assert/strict";
import { execFileSync } from "node:child_process";
import { existsSync, mkdtempSync, readFileSync, writeFileSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { benchy, clearWorkerLog, downloadText, openPage, pick, recordWorkerMessages, repo, startForTests, waitDone, workerLog } from "./helpers.mjs";

const env = startForTests();
const tmp = mkdtempSync(join(tmpdir(), "dropslice-draft-"));
const cli = join(repo, "target/release/dropslice");

after(() => execFileSync("rm", ["-rf", tmp]));

/** A page that records the messages to and from its workers (`recordWorkerMessages`), settled
 *  on the sample part. */
async function recorded(browser, url) {
  const opened = await openPage(browser, url);
  await recordWorkerMessages(opened.page);
  await opened.page.reload();
  await waitDone(opened.page, 60_000); // the sample part
  return opened;
}

/** Slices `file` on two workers: the requests posted meanwhile (by kind: the workers they
 *  went to) and the downloaded .gco's text. */
async function sliceOnTwo(file) {
  const { page, context } = await recorded(env.browser, `${env.url}?workers=2`);
  try {
    await clearWorkerLog(page);
    await pick(page, file);
    const s = await waitDone(page, 240_000);
    assert.equal(s.workers, 2);
    const to = {};
    for (const [, w, dir, kind] of await workerLog(page)) if (dir === "→") (to[kind] ??= []).push(w);
    return { to, text: await downloadText(page) };
  } finally {
    await context.close();
  }
}

/** Asserts the page's .gco is the CLI's, naming the first line that differs. The page slices
 *  a file as a build job of one part, which its header's part line calls "(arranged)"; the
 *  CLI's single file is not a build job. Every other byte is the same. */
function assertSameText(mine, cli) {
  const page = mine.replace(/^(; part 1 = .*) \(arranged\),/m, "$1,");
  if (page === cli) return;
  const [a, b] = [page.split("\n"), cli.split("\n")];
  const i = a.findIndex((l, k) => l !== b[k]);
  assert.fail(`the page's .gco differs from the CLI's at line ${i + 1}: ${JSON.stringify(a[i])} against ${JSON.stringify(b[i])}`);
}

function cliText(file) {
  const out = join(tmp, "cli.gco");
  execFileSync(cli, [file, "-o", out, "-q"], { stdio: "inherit" });
  return readFileSync(out, "utf8");
}

test("3DBenchy: the other worker slices from the draft, confirmed; the .gco is the CLI's", async (t) => {
  if (!existsSync(cli)) return t.skip("target/release/dropslice not built");
  const { to, text } = await sliceOnTwo(benchy);
  assert.equal(to.adopt_draft?.length, 1, "one draft taken");
  assert.deepEqual(to.confirm_job, to.adopt_draft, "confirmed in the worker that took the draft");
  assert.equal(to.adopt_job, undefined, "no prepared job handed over");
  assert.ok(to.slice.includes(to.adopt_draft[0]), "the draft's worker sliced");
  assertSameText(text, cliText(benchy));
});

test("3DBenchy inside out: the draft does not stand, a fresh worker takes the prepared job; the .gco is the CLI's", async (t) => {
  if (!existsSync(cli)) return t.skip("target/release/dropslice not built");
  // every facet turned (its second and third corners swapped): the one shell is turned back
  const stl = Buffer.from(readFileSync(benchy));
  const n = stl.readUInt32LE(80);
  for (let i = 0; i < n; i++) {
    const at = 84 + 50 * i + 24;
    const second = Buffer.from(stl.subarray(at, at + 12));
    stl.copy(stl, at, at + 12, at + 24);
    second.copy(stl, at + 12);
  }
  const file = join(tmp, "3DBenchy.stl");
  writeFileSync(file, stl);
  const { to, text } = await sliceOnTwo(file);
  assert.equal(to.adopt_draft?.length, 1, "one draft taken");
  assert.equal(to.confirm_job, undefined, "not confirmed");
  // Whether the draft's worker took units before it was dropped (they are given back), and
  // how many the fresh worker gets, depends on the machine's load; the bytes must not.
  assert.equal(to.adopt_job?.length, 1, "the prepared job handed over");
  assert.notEqual(to.adopt_job[0], to.adopt_draft[0], "to a fresh worker");
  assertSameText(text, cliText(file));
});

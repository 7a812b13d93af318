// The speed table of docs/performance.md (issue 40's table) in one run (`npm run bench`): on
// 3DBenchy, the CLI against CuraEngine, support on against off, `--report` against plain, the
// page (file chosen → every layer's G-code ready, the page's own clock) against the CLI in a
// fresh page and on a second visit (a new page of the same browser profile), the page's longest
// main-thread task while slicing; stanford_bunny `--report` against plain; the 1M torus in the
// page against the CLI; 10⁵ separate 0.5 mm cubes (scripts/many_parts.py fan 5) against
// 3DBenchy on the CLI and 10⁶ cubes (fan 6, a minute or more per run: BENCH_CUBES6_RUNS runs,
// default 1, no warm-up) against 10⁵; then the peak memory (RSS) of every CLI run and of
// CuraEngine. Every other figure is a median of BENCH_RUNS (default 5) runs after one untimed
// warm-up, the runs of the tools compared interleaved (run k of each, then run k + 1), so a
// burst of other work on the machine falls on all of them alike. Ratios are of wall times; CPU
// (user + sys) is printed beside.
//
// Environment: BENCH_RUNS (5), BENCH_BUILD (1: cargo build --release --bin dropslice and
// scripts/build.sh first; 0: use what is built), BENCH_PAGE (1; 0: CLI figures only),
// BENCH_PROFILE (1: also print the page's per-stage profile, from the page's and the
// workers' counters), BENCH_DIR (target/bench: the private CLI copy, the generated torus,
// Cura's definitions, the raw runs in table.json), PYTHON (a python3 with numpy for
// shared/tools/gen_mesh.py; default target/pyenv's), DROPSLICE_SHARED (../shared), CURA_DEFS
// (the folder of Cura's fdmprinter.def.json; else unpacked from Debian's `cura` package),
// BENCH_INSTALL (1: install CuraEngine from Debian if it is missing; 0: do not), BENCH_CUBES6
// (1; 0: not the 10⁶ cubes), BENCH_CUBES6_RUNS (1).
//
// CuraEngine runs with shared/bench/peers.sh's matched FDM settings (its run_cura, read out of
// that file): the same 240 layers, 100 % fill. Where CuraEngine is not installed (Debian
// package cura-engine) the CLI's time is printed and the ratio is marked as not measured.
import { execFileSync, spawnSync } from "node:child_process";
import { copyFileSync, existsSync, mkdirSync, mkdtempSync, readFileSync, readdirSync, rmSync, statSync, writeFileSync } from "node:fs";
import { tmpdir } from "node:os";
import { dirname, join, resolve } from "node:path";
import { fileURLToPath } from "node:url";

const repo = resolve(dirname(fileURLToPath(import.meta.url)), "..");
const shared = resolve(process.env.DROPSLICE_SHARED ?? join(repo, "../shared"));
const dir = resolve(process.env.BENCH_DIR ?? join(repo, "target/bench"));
const runs = Math.max(1, Number(process.env.BENCH_RUNS ?? 5) | 0);
const build = process.env.BENCH_BUILD !== "0";
const withPage = process.env.BENCH_PAGE !== "0";
const profile = process.env.BENCH_PROFILE === "1";
const benchy = join(shared, "models/3DBenchy.stl");
const bunny = join(shared, "models/stanford_bunny.stl");
mkdirSync(join(dir, "bin"), { recursive: true });
mkdirSync(join(dir, "models"), { recursive: true });
mkdirSync(join(dir, "out"), { recursive: true });
const log = (m) => console.error(`[bench ${new Date().toISOString().slice(11, 19)}] ${m}`);
const load = () => readFileSync("/proc/loadavg", "utf8").split(" ")[0];

// ------------------------------------------------------------------ build
if (build) {
  log("cargo build --release --bin dropslice");
  execFileSync("cargo", ["build", "--release", "--bin", "dropslice"], { cwd: repo, stdio: ["ignore", 2, 2] });
  if (withPage) {
    log("bash scripts/build.sh");
    execFileSync("bash", ["scripts/build.sh"], { cwd: repo, stdio: ["ignore", 2, 2] });
  }
}
// a private copy: another build during the run cannot swap the binary
const ds = join(dir, "bin/dropslice");
copyFileSync(join(repo, "target/release/dropslice"), ds);

// ------------------------------------------------------------------ models
function torus1m() {
  const f = join(dir, "models/torus_1000000.stl");
  if (!existsSync(f) || statSync(f).size === 0) {
    log("generating the 1M torus (shared/tools/gen_mesh.py -n 1000000)");
    // gen_mesh.py needs numpy: the project's environment (scripts/setup.sh), else PYTHON or python3
    const py = [process.env.PYTHON, join(repo, "target/pyenv/bin/python3"), "python3"].filter(Boolean).find((p) => p === "python3" || existsSync(p));
    execFileSync(py, [join(shared, "tools/gen_mesh.py"), "-n", "1000000", "-o", `${f}.tmp`], { stdio: ["ignore", 2, 2] });
    execFileSync("mv", [`${f}.tmp`, f]);
  }
  return f;
}
const torus = torus1m();

/** 10^levels separate inside-out 0.5 mm cubes on a 1 mm grid (a 3MF of components). */
function cubes(levels) {
  const f = join(dir, `models/cubes_fan${levels}.3mf`);
  if (!existsSync(f)) execFileSync("python3", [join(repo, "scripts/many_parts.py"), "fan", String(levels), f], { stdio: ["ignore", 2, 2] });
  return f;
}
const cubes5 = cubes(5);
const cubes6 = process.env.BENCH_CUBES6 !== "0" ? cubes(6) : null;
const cubes6Runs = Math.max(1, Number(process.env.BENCH_CUBES6_RUNS ?? 1) | 0);

// ------------------------------------------------------------------ CuraEngine
function curaCommand() {
  const has = () => spawnSync("bash", ["-c", "command -v CuraEngine"]).status === 0;
  if (!has() && process.env.BENCH_INSTALL !== "0") {
    // as scripts/bench.sh does: Debian's package (root, or sudo)
    log("installing CuraEngine (apt-get install cura-engine)");
    const sudo = process.getuid?.() === 0 ? "" : "sudo ";
    spawnSync("bash", ["-c", `${sudo}apt-get update -qq && DEBIAN_FRONTEND=noninteractive ${sudo}apt-get install -y -qq --no-install-recommends cura-engine`], { stdio: ["ignore", 2, 2] });
  }
  if (!has()) return { missing: "CuraEngine is not installed and could not be (Debian: apt-get install cura-engine)" };
  const peers = join(shared, "bench/peers.sh");
  if (!existsSync(peers)) return { missing: `${peers} is missing` };
  const m = readFileSync(peers, "utf8").match(/^run_cura\(\) \{\n[\s\S]*?^\}/m);
  if (!m) return { missing: `run_cura() not found in ${peers}` };
  let defs = process.env.CURA_DEFS;
  for (const d of [defs, "/usr/share/cura/resources/definitions", join(dir, "cura-deb/usr/share/cura/resources/definitions")]) {
    if (d && existsSync(join(d, "fdmprinter.def.json"))) {
      defs = d;
      break;
    }
  }
  if (!defs || !existsSync(join(defs, "fdmprinter.def.json"))) {
    log("unpacking Cura's machine definitions (apt-get download cura)");
    const r = spawnSync("bash", ["-c", `cd '${dir}' && rm -f cura_*.deb && apt-get download cura && dpkg-deb -x cura_*.deb cura-deb`], { stdio: ["ignore", 2, 2] });
    defs = join(dir, "cura-deb/usr/share/cura/resources/definitions");
    if (r.status !== 0 || !existsSync(join(defs, "fdmprinter.def.json"))) return { missing: "Cura's fdmprinter.def.json is missing (Debian package cura)" };
  }
  return { script: `${m[0]}\nCURA_DEFS='${defs}'; run_cura "$1" "$2"` };
}
const cura = curaCommand();
if (cura.missing) log(`CuraEngine: ${cura.missing}; the CLI/CuraEngine ratio cannot be measured here`);

// ------------------------------------------------------------------ runs
/** Runs argv under /usr/bin/time; returns { wall, cpu } in seconds and the peak RSS in MB
 *  (throws on failure). */
function timed(argv) {
  const tf = join(dir, "out/time.txt");
  const r = spawnSync("/usr/bin/time", ["-f", "%e %U %S %M", "-o", tf, ...argv], { encoding: "utf8", maxBuffer: 1 << 26 });
  if (r.status !== 0) throw new Error(`${argv.join(" ")} failed (${r.status}): ${(r.stderr ?? "").slice(-500)}`);
  const [wall, user, sys, kb] = readFileSync(tf, "utf8").trim().split("\n").pop().split(" ").map(Number);
  return { wall, cpu: user + sys, rss: kb / 1024 };
}
const out = (name) => join(dir, `out/${name}`);
const cli = {
  plain: () => timed([ds, "-q", benchy, "-o", out("benchy.gco")]),
  support: () => timed([ds, "-q", benchy, "-o", out("benchy_s.gco"), "--set", "support=unit1"]),
  report: () => timed([ds, "-q", benchy, "-o", out("benchy_r.gco"), "--report", out("benchy_r.json")]),
  bunny: () => timed([ds, "-q", bunny, "-o", out("bunny.gco"), "--set", "allow_off_plate=true"]),
  bunnyReport: () => timed([ds, "-q", bunny, "-o", out("bunny_r.gco"), "--set", "allow_off_plate=true", "--report", out("bunny_r.json")]),
  torus: () => timed([ds, "-q", torus, "-o", out("torus.gco")]),
  cubes5: () => timed([ds, "-q", cubes5, "-o", out("cubes5.gco")]),
  cubes6: () => timed([ds, "-q", cubes6, "-o", out("cubes6.gco")]),
};
if (cura.script) cli.cura = () => timed(["bash", "-c", cura.script, "run_cura", benchy, out("benchy.cura.gcode")]);

const samples = {}; // name -> [{wall, cpu}] (or page: {seconds, longtask, gap})
const add = (k, v) => (samples[k] ??= []).push(v);
const median = (xs) => {
  const s = [...xs].sort((a, b) => a - b);
  const n = s.length;
  return n === 0 ? NaN : n % 2 ? s[(n - 1) / 2] : (s[n / 2 - 1] + s[n / 2]) / 2;
};

async function pageRunner() {
  const { start, openPage, waitSettled, watchLongTasks, longTasks } = await import(join(repo, "tests/e2e/helpers.mjs"));
  const env = await start();
  /** Slices `file` in a fresh page; { seconds, longtask, gap, layers, workers, stages }. */
  async function once(file) {
    const { page, context } = await openPage(env.browser, env.url);
    try {
      await waitSettled(page); // the sample part of the first visit
      // the page's long tasks and the longest gap of a 16 ms timer from here on
      await watchLongTasks(page);
      if (profile) {
        await page.evaluate(() => globalThis.__dropsliceStages?.reset());
        for (const wk of page.workers()) await wk.evaluate(() => globalThis.__dropsliceStages?.reset()).catch(() => {});
      }
      await page.setInputFiles("#file-input", file);
      const s = await waitSettled(page, 900_000);
      if (s.state !== "done") throw new Error(`${file}: the page ended in state ${s.state}`);
      const w = await longTasks(page);
      // the page's counters, then each worker's (the core's counters among them)
      const stages = [];
      if (profile) {
        stages.push(await page.evaluate(() => globalThis.__dropsliceStages?.read() ?? {}));
        for (const wk of page.workers()) {
          const st = await wk.evaluate(() => globalThis.__dropsliceStages?.read() ?? null).catch(() => null);
          if (st) stages.push(st);
        }
      }
      const longtask = w.tasks.reduce((m, [, d]) => Math.max(m, d), 0);
      return { seconds: s.seconds, longtask, tasks: w.tasks.length, gap: w.gap, layers: s.layers, workers: s.workers, stages };
    } finally {
      await context.close();
    }
  }
  // A second visit: a new page of one browser profile kept for the whole run (its HTTP cache
  // and the engine's code cache), as scripts/page_revisit_time.mjs measures it; the warm-up
  // round's visit is that profile's first.
  const { chromium } = await import("playwright-core");
  const { chromiumPath } = await import(join(repo, "tests/e2e/helpers.mjs"));
  const profileDir = mkdtempSync(join(tmpdir(), "dropslice-bench-profile-"));
  const kept = await chromium.launchPersistentContext(profileDir, {
    executablePath: chromiumPath,
    headless: true,
    viewport: { width: 1440, height: 900 },
    args: ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run", "--disable-background-networking", "--disable-component-update", "--disable-sync"],
  });
  /** Slices `file` in a new page of the kept profile; { seconds, longtask: 0, gap: 0, ... }. */
  async function revisit(file) {
    const p = await kept.newPage();
    try {
      await p.goto(env.url);
      await waitSettled(p); // the sample part
      await p.evaluate(() => (document.body.dataset.state = "picking"));
      await p.setInputFiles("#file-input", file);
      const s = await waitSettled(p, 900_000);
      if (s.state !== "done") throw new Error(`${file}: the page ended in state ${s.state}`);
      // the code cache is written after the load: give it time before the next visit
      await p.waitForTimeout(3000);
      return { seconds: s.seconds, longtask: 0, tasks: 0, gap: 0, layers: s.layers, workers: s.workers, stages: [] };
    } finally {
      await p.close();
    }
  }
  return {
    once,
    revisit,
    close: async () => {
      await kept.close().catch(() => {});
      rmSync(profileDir, { recursive: true, force: true });
      await env.close();
    },
  };
}

const page = withPage ? await pageRunner() : null;
try {
  // each step: one run of every tool, in this order; the first round is the warm-up
  const steps = [
    ["cli", () => cli.plain()],
    ...(cli.cura ? [["cura", () => cli.cura()]] : []),
    ["support", () => cli.support()],
    ["report", () => cli.report()],
    ...(page ? [["page", () => page.once(benchy)]] : []),
    ...(page ? [["page_revisit", () => page.revisit(benchy)]] : []),
    ["cli2", () => cli.plain()],
    ["bunny", () => cli.bunny()],
    ["bunny_report", () => cli.bunnyReport()],
    ["torus_cli", () => cli.torus()],
    ...(page ? [["torus_page", () => page.once(torus)]] : []),
    ["cubes5", () => cli.cubes5()],
    ...(cubes6 ? [["cubes6", () => cli.cubes6()]] : []),
  ];
  for (let k = 0; k <= runs; k++) {
    for (const [name, run] of steps) {
      if (name === "cubes6" && (k === 0 || k > cubes6Runs)) continue;
      const l = load();
      const v = await run();
      if (k > 0) add(name, v);
      const what = "wall" in v ? `${v.wall.toFixed(2)} s wall, ${v.cpu.toFixed(2)} s CPU, ${v.rss.toFixed(0)} MB` : `${v.seconds.toFixed(2)} s, longest task ${v.longtask.toFixed(0)} ms (${v.tasks} over 50 ms), timer gap ${v.gap.toFixed(0)} ms, ${v.workers} workers`;
      log(`${k ? `run ${k}` : "warm-up"} ${name}: ${what} (load ${l})`);
    }
  }
} finally {
  await page?.close();
}

// ------------------------------------------------------------------ report
const med = (k, f = "wall") => median((samples[k] ?? []).map((v) => v[f]));
const cliWall = median([...(samples.cli ?? []), ...(samples.cli2 ?? [])].map((v) => v.wall));
const cliCpu = median([...(samples.cli ?? []), ...(samples.cli2 ?? [])].map((v) => v.cpu));
const f2 = (x) => (Number.isFinite(x) ? x.toFixed(2) : "–");
const f3 = (x) => (Number.isFinite(x) ? x.toFixed(3) : "–");
const verdict = (x, target) => (Number.isFinite(x) ? (x <= target ? "met" : "NOT met") : "not measured");
const rows = [];
const row = (figure, value, ratio, target) => rows.push([figure, value, ratio, `≤ ${target}`, verdict(ratio, target)]);
if (cli.cura) {
  row("CLI / CuraEngine 4.13 (3DBenchy, wall)", `${f2(cliWall)} / ${f2(med("cura"))} s (CPU ${f2(cliCpu)} / ${f2(med("cura", "cpu"))})`, cliWall / med("cura"), 0.12);
} else {
  rows.push(["CLI / CuraEngine 4.13 (3DBenchy)", `CLI ${f2(cliWall)} s (CPU ${f2(cliCpu)}); ${cura.missing}`, "–", "≤ 0.12", "not measured"]);
}
row("support on / off (3DBenchy, wall)", `${f2(med("support"))} / ${f2(cliWall)} s (CPU ${f2(med("support", "cpu"))} / ${f2(cliCpu)})`, med("support") / cliWall, 1.25);
row("--report / plain (3DBenchy, wall)", `${f2(med("report"))} / ${f2(cliWall)} s (CPU ${f2(med("report", "cpu"))} / ${f2(cliCpu)})`, med("report") / cliWall, 1.5);
row("--report / plain (stanford_bunny, wall)", `${f2(med("bunny_report"))} / ${f2(med("bunny"))} s (CPU ${f2(med("bunny_report", "cpu"))} / ${f2(med("bunny", "cpu"))})`, med("bunny_report") / med("bunny"), 3);
if (page) {
  const p = median(samples.page.map((v) => v.seconds));
  row(`page / CLI (3DBenchy, a fresh page, ${samples.page[0].workers} workers)`, `${f2(p)} / ${f2(cliWall)} s`, p / cliWall, 2);
  const pr = median(samples.page_revisit.map((v) => v.seconds));
  row("page / CLI (3DBenchy, a second visit: a new page of the same browser profile)", `${f2(pr)} / ${f2(cliWall)} s`, pr / cliWall, 1.5);
  const lt = Math.max(...samples.page.map((v) => v.longtask), ...samples.torus_page.map((v) => v.longtask));
  const gap = Math.max(...samples.page.map((v) => v.gap), ...samples.torus_page.map((v) => v.gap));
  rows.push(["page's longest main-thread task while slicing (both models, all runs)", `${lt > 0 ? `${lt.toFixed(0)} ms` : "none over 50 ms"} (longest 16 ms timer gap ${gap.toFixed(0)} ms)`, lt > 0 ? f2(lt / 1000) : "0", "≤ 50 ms", lt <= 50 ? "met" : "NOT met"]);
  const tp = median(samples.torus_page.map((v) => v.seconds));
  const tc = med("torus_cli");
  row("page / CLI (1M torus)", `${f2(tp)} / ${f2(tc)} s (CLI CPU ${f2(med("torus_cli", "cpu"))})`, tp / tc, 2);
}
row("10⁵ cubes / 3DBenchy (CLI, wall)", `${f2(med("cubes5"))} / ${f2(cliWall)} s (CPU ${f2(med("cubes5", "cpu"))} / ${f2(cliCpu)})`, med("cubes5") / cliWall, 2);
if (cubes6) row(`10⁶ cubes / 10⁵ cubes (CLI, wall; 10⁶: ${cubes6Runs} run${cubes6Runs > 1 ? "s" : ""})`, `${f2(med("cubes6"))} / ${f2(med("cubes5"))} s (CPU ${f2(med("cubes6", "cpu"))} / ${f2(med("cubes5", "cpu"))})`, med("cubes6") / med("cubes5"), 10);
else rows.push(["10⁶ cubes / 10⁵ cubes (CLI)", "skipped (BENCH_CUBES6=0)", "–", "≤ 10", "not measured"]);
// peak memory of every CLI run (median of the runs' peak RSS)
const memory = [
  ["3DBenchy", "cli"],
  ["3DBenchy, CuraEngine 4.13", "cura"],
  ["3DBenchy, support on", "support"],
  ["3DBenchy, --report", "report"],
  ["stanford_bunny", "bunny"],
  ["stanford_bunny, --report", "bunny_report"],
  ["1M torus", "torus_cli"],
  ["10⁵ cubes", "cubes5"],
  ["10⁶ cubes", "cubes6"],
].filter(([, k]) => samples[k]?.length);
const meta = `commit ${execFileSync("git", ["-C", repo, "describe", "--always", "--dirty"], { encoding: "utf8" }).trim()}, ${new Date().toISOString().slice(0, 16)}Z, ${runs} runs each (median, interleaved), load now ${load()}`;
const table = [
  meta,
  "",
  "| figure | measured | ratio | target | verdict |",
  "|---|---|---:|---|---|",
  ...rows.map((r) => `| ${r[0]} | ${r[1]} | ${typeof r[2] === "number" ? f3(r[2]) : r[2]} | ${r[3]} | ${r[4]} |`),
  "",
  "| peak memory (RSS, median of the runs) | MB |",
  "|---|---:|",
  ...memory.map(([what, k]) => `| ${what} | ${med(k, "rss").toFixed(0)} |`),
].join("\n");
console.log(table);
writeFileSync(join(dir, "table.md"), `${table}\n`);
writeFileSync(join(dir, "table.json"), JSON.stringify({ meta, samples }, null, 1));
if (page && profile) console.log(`\n${stageTable(samples.page, "3DBenchy")}\n\n${stageTable(samples.torus_page, "1M torus")}`);
for (const f of readdirSync(join(dir, "out"))) rmSync(join(dir, "out", f)); // big; the figures are kept

/** The workers' per-stage counters, median over runs of the sum over workers, ms. */
function stageTable(list, what) {
  const names = [...new Set(list.flatMap((r) => r.stages.flatMap((s) => Object.keys(s))))];
  if (names.length === 0) return `(${what}: the workers kept no stage counters)`;
  const lines = [`page stages, ${what} (ms, summed over the workers, median of the runs)`, "", "| stage | ms |", "|---|---:|"];
  for (const n of names) lines.push(`| ${n} | ${median(list.map((r) => r.stages.reduce((a, s) => a + (s[n] ?? 0), 0))).toFixed(0)} |`);
  return lines.join("\n");
}

// The page's long main-thread tasks while it slices a model, and what runs in each
// (docs/performance.md, "The page's long tasks"). For every run: a fresh page settles on the
// sample part; then, as `npm run bench` does, a `PerformanceObserver` for `longtask` and a
// 16 ms timer watch the page's thread (tests/e2e/helpers.mjs `watchLongTasks`) while a
// Chromium trace is recorded (the timeline, V8's sampling profiler) until every layer's G-code
// is ready. Printed per run: the observer's figures; the page's thread from the file chosen on
// (its tasks, their CPU, the time by phase: script, style, layout, paint, commit, GC; the
// page's own functions over all of it); then every task over LIMIT_MS of wall time or CPU_MS
// of CPU: when it ran (ms from the file chosen; before it: what followed the sample part), its
// wall time and its thread's CPU, the page's state then (`body[data-state]`), its phases (CPU
// and wall), the callbacks it ran (an animation frame, a timer, a worker's message, a
// `ResizeObserver`, named by function), and its functions by self time and by the page's own
// code with what they called ("(program)": the browser's own work outside script), named
// through the source maps of dist/.
//
// Usage, after `bash scripts/build.sh`:
//   node scripts/page_longtasks.mjs [MODEL ...]   (default: 3DBenchy)
// Environment: RUNS (per model, default 2); LIMIT_MS (default 50); CPU_MS (default 20: on a
// loaded machine a task's wall time is mostly waiting for a core, its CPU is what it costs);
// TRACE=0 (the observer and the timer alone, as the bench measures: no trace); TOP (functions
// a task, default 6); CATEGORIES (more trace categories, comma-separated); DEBUG=1 (every event
// over 1 ms in each task listed); DROPSLICE_DIST (another build). The trace slows the page's
// thread a little.
import { readFileSync } from "node:fs";
import { dirname, join, resolve } from "node:path";
import { fileURLToPath } from "node:url";

const repo = resolve(dirname(fileURLToPath(import.meta.url)), "..");
const { start, openPage, waitSettled, benchy, watchLongTasks, longTasks } = await import(join(repo, "tests/e2e/helpers.mjs"));
const dist = resolve(process.env.DROPSLICE_DIST ?? join(repo, "dist"));
const models = process.argv.slice(2).length ? process.argv.slice(2) : [benchy];
const runs = Number(process.env.RUNS ?? 2);
const limit = Number(process.env.LIMIT_MS ?? 50);
const trace = process.env.TRACE !== "0";
const top = Number(process.env.TOP ?? 6);
const cpuLimit = Number(process.env.CPU_MS ?? 20);

const CATEGORIES = [
  "toplevel",
  "devtools.timeline",
  "disabled-by-default-devtools.timeline",
  "disabled-by-default-devtools.timeline.frame",
  "v8.execute",
  "v8",
  "blink.user_timing",
  "disabled-by-default-v8.cpu_profiler",
  "disabled-by-default-v8.gc",
  ...(process.env.CATEGORIES ? process.env.CATEGORIES.split(",") : []),
];

// ------------------------------------------------------------------ source maps
const B64 = new Map([..."ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/"].map((c, i) => [c, i]));

/** A source map's segments by generated line: [column, source, line, column, name?] each. */
function decodeMap(map) {
  const lines = [];
  const state = [0, 0, 0, 0, 0]; // source, line, column, name carry over lines; column resets
  for (const text of map.mappings.split(";")) {
    const segs = [];
    let col = 0;
    for (const seg of text.split(",")) {
      if (!seg) continue;
      const v = [];
      let value = 0;
      let shift = 0;
      for (const c of seg) {
        const d = B64.get(c);
        value += (d & 31) << shift;
        if (d & 32) shift += 5;
        else {
          v.push(value & 1 ? -(value >>> 1) : value >>> 1);
          value = 0;
          shift = 0;
        }
      }
      col += v[0];
      if (v.length >= 4) {
        state[0] += v[1];
        state[1] += v[2];
        state[2] += v[3];
        if (v.length >= 5) state[3] += v[4];
        segs.push([col, state[0], state[1], state[2], v.length >= 5 ? state[3] : -1]);
      }
    }
    lines.push(segs);
  }
  return lines;
}

const maps = new Map(); // script file name -> { map, lines } | null
/** "file:line name" of a generated position (0-based line and column) of a script of dist/. */
function original(url, line, column) {
  const file = (url || "").split("/").pop().split("?")[0];
  if (!file.endsWith(".js")) return null;
  if (!maps.has(file)) {
    try {
      const map = JSON.parse(readFileSync(join(dist, `${file}.map`), "utf8"));
      maps.set(file, { map, lines: decodeMap(map) });
    } catch {
      maps.set(file, null);
    }
  }
  const m = maps.get(file);
  const segs = m?.lines[line];
  if (!segs?.length) return null;
  let best = segs[0];
  for (const s of segs) if (s[0] <= column) best = s;
  const src = m.map.sources[best[1]].replace(/^(\.\.\/)+/, "");
  // the name of the function: the mapping's own name, else the words after the position
  let name = best[4] >= 0 ? m.map.names[best[4]] : "";
  const text = m.map.sourcesContent?.[best[1]]?.split("\n")[best[2]] ?? "";
  if (!name) name = (/[\w$.]+/.exec(text.slice(best[3])) ?? [""])[0];
  return { where: `${src}:${best[2] + 1}`, name, text: text.trim().slice(0, 70) };
}

/** A profile node's or an event's function in words. */
function frameName(cf) {
  const o = cf.url ? original(cf.url, cf.lineNumber, cf.columnNumber) : null;
  if (o) return `${o.name || cf.functionName || "(anonymous)"} (${o.where})`;
  if (!cf.url) return cf.functionName || "(native)";
  return `${cf.functionName || "(anonymous)"} (${cf.url.split("/").pop()}:${cf.lineNumber + 1})`;
}
const ours = (cf) => /\/(main|chunk-[\w-]+)\.js$/.test((cf.url || "").split("?")[0]);

// ------------------------------------------------------------------ the trace
/** The long tasks of the page's main thread in `events`, each with its breakdown. */
function analyse(events, fromUs, t0us) {
  // the page's main thread: the CrRendererMain with the most top-level task time
  const names = new Map();
  for (const e of events) if (e.ph === "M" && e.name === "thread_name") names.set(`${e.pid}:${e.tid}`, e.args.name);
  const busy = new Map();
  for (const e of events) {
    if (e.ph === "X" && e.name === "RunTask" && names.get(`${e.pid}:${e.tid}`) === "CrRendererMain") busy.set(`${e.pid}:${e.tid}`, (busy.get(`${e.pid}:${e.tid}`) ?? 0) + e.dur);
  }
  const main = [...busy].sort((a, b) => b[1] - a[1])[0]?.[0];
  if (!main) throw new Error("no main thread of a page in the trace");
  const onMain = events.filter((e) => `${e.pid}:${e.tid}` === main);
  const marks = onMain.filter((e) => e.cat?.includes("blink.user_timing") && e.name.startsWith("dropslice:")).map((e) => [e.ts, e.name.slice(10)]).sort((a, b) => a[0] - b[0]);
  const all = onMain.filter((e) => e.ph === "X" && e.name === "RunTask" && e.ts >= fromUs);
  const tasks = all.filter((e) => e.dur >= limit * 1000 || (e.tdur ?? 0) >= cpuLimit * 1000).sort((a, b) => a.ts - b.ts);
  const cpuMax = all.reduce((m, e) => Math.max(m, (e.tdur ?? 0) / 1000), 0);
  const inner = onMain.filter((e) => e.ph === "X" && e.name !== "RunTask" && e.dur > 0);

  // the sampling profiler's samples of the main thread: [ts, node], nodes by id
  const nodes = new Map();
  const samples = [];
  const profiles = new Map(); // id -> { start, last }
  for (const e of events) {
    if (`${e.pid}:${e.tid}` !== main) continue;
    if (e.name === "Profile") profiles.set(e.id, { last: e.args.data.startTime });
  }
  for (const e of events) {
    if (e.name !== "ProfileChunk" || !profiles.has(e.id)) continue;
    const p = profiles.get(e.id);
    const d = e.args.data;
    for (const n of d.cpuProfile?.nodes ?? []) nodes.set(`${e.id}:${n.id}`, { ...n, key: `${e.id}:${n.id}`, parentKey: n.parent !== undefined ? `${e.id}:${n.parent}` : null });
    const ids = d.cpuProfile?.samples ?? [];
    const deltas = d.timeDeltas ?? [];
    for (let i = 0; i < ids.length; i++) {
      p.last += deltas[i] ?? 0;
      samples.push([p.last, `${e.id}:${ids[i]}`]);
    }
  }
  samples.sort((a, b) => a[0] - b[0]);
  const urls = new Map(); // scriptId -> url (trace events name scripts by id)
  for (const n of nodes.values()) if (n.callFrame.url) urls.set(String(n.callFrame.scriptId), n.callFrame.url);

  // the phases of a time span: each event counted where it is outermost among its kind
  // (script, style, layout, …); a style or layout inside script is the script forcing it
  const PHASES = [
    ["script", /^(FunctionCall|EventDispatch|TimerFire|FireAnimationFrame|FireIdleCallback|EvaluateScript|v8\.callFunction|RunMicrotasks|ParseHTML)$/],
    ["style", /^(UpdateLayoutTree|RecalculateStyles)$/],
    ["layout", /^Layout$/],
    ["pre-paint", /^PrePaint$/],
    ["paint", /^Paint$/],
    ["layerize", /^Layerize$/],
    ["commit", /^Commit$/],
    ["GC", /^(MinorGC|MajorGC)$/],
  ];
  const phasesOf = (within) => {
    const phases = new Map();
    const outer = new Map(); // phase -> outermost events, in order
    const sorted = [...within].sort((x, y) => x.ts - y.ts || y.dur - x.dur);
    for (const [phase, re] of PHASES) {
      let end = -Infinity;
      const list = [];
      for (const e of sorted) {
        if (!re.test(e.name) || e.ts + e.dur <= end) continue;
        list.push(e);
        end = e.ts + e.dur;
      }
      outer.set(phase, list);
    }
    const scripts = outer.get("script");
    let k = 0;
    for (const [phase, list] of outer) {
      for (const e of list) {
        let inScript = false;
        if (phase !== "script" && phase !== "GC") {
          // the script events are sorted and apart: the last one starting before e
          while (k > 0 && scripts[k - 1].ts > e.ts) k--;
          while (k < scripts.length && scripts[k].ts <= e.ts) k++;
          const o = scripts[k - 1];
          inScript = o !== undefined && o.ts + o.dur >= e.ts + e.dur;
        }
        const key = inScript ? `${phase} forced by script` : phase;
        const [w, c] = phases.get(key) ?? [0, 0];
        phases.set(key, [w + e.dur / 1000, c + (e.tdur ?? 0) / 1000]);
      }
      k = 0;
    }
    return { phases: [...phases].sort((x, y) => y[1][1] - x[1][1]).filter(([, [w]]) => w >= 0.5), scripts };
  };
  // by the page's innermost own function (what it called included) and by self time
  const profileOf = (t0, t1) => {
    const inSpan = samples.filter(([ts]) => ts >= t0 && ts < t1);
    const step = inSpan.length > 1 ? (inSpan[inSpan.length - 1][0] - inSpan[0][0]) / (inSpan.length - 1) / 1000 : 0;
    const self = new Map();
    const own = new Map();
    for (const [, key] of inSpan) {
      const n = nodes.get(key);
      if (!n) continue;
      const name = frameName(n.callFrame);
      self.set(name, (self.get(name) ?? 0) + step);
      let o = n;
      while (o && !ours(o.callFrame)) o = o.parentKey ? nodes.get(o.parentKey) : null;
      // the chain of the page's own functions, innermost first, three deep
      const chain = [];
      for (let c = o; c && chain.length < 3; c = c.parentKey ? nodes.get(c.parentKey) : null) if (ours(c.callFrame)) chain.push(frameName(c.callFrame));
      const k = chain.length ? chain.join(" ← ") : `(outside the page's code: ${name})`;
      own.set(k, (own.get(k) ?? 0) + step);
    }
    const rank = (m) => [...m].sort((a, b) => b[1] - a[1]).slice(0, top).filter(([, v]) => v >= 0.5);
    return { self: rank(self), own: rank(own) };
  };

  const whole = phasesOf(inner.filter((e) => e.ts >= t0us));
  const totals = { tasks: all.filter((e) => e.ts >= t0us).length, cpu: all.filter((e) => e.ts >= t0us).reduce((a, e) => a + (e.tdur ?? 0), 0) / 1000, phases: whole.phases, ...profileOf(t0us, Infinity) };
  const out = [];
  for (const t of tasks) {
    const end = t.ts + t.dur;
    const within = inner.filter((e) => e.ts >= t.ts && e.ts < end);
    const { phases, scripts } = phasesOf(within);
    // what each outermost script event ran: the first function call in it, named
    const describe = (e) => {
      const d = e.args?.data ?? {};
      let what = { FireAnimationFrame: "animation frame", TimerFire: "timer", EventDispatch: `event ${d.type ?? ""}`, FireIdleCallback: "idle callback", RunMicrotasks: "microtasks" }[e.name] ?? e.name;
      const call = [e, ...within].find((c) => c.name === "FunctionCall" && c.ts >= e.ts && c.ts + c.dur <= e.ts + e.dur);
      const c = call?.args?.data;
      if (c && (c.url || c.scriptId)) {
        const url = c.url || urls.get(String(c.scriptId)) || "";
        what += ` → ${frameName({ functionName: c.functionName, url, lineNumber: (c.lineNumber ?? 1) - 1, columnNumber: (c.columnNumber ?? 1) - 1 })}`;
      }
      return `${what} ${(e.dur / 1000).toFixed(1)} ms`;
    };
    if (process.env.DEBUG) {
      for (const e of within.filter((e) => e.dur >= 1000)) console.log(`      [${((e.ts - t.ts) / 1000).toFixed(1)} +${(e.dur / 1000).toFixed(1)}] ${e.name} ${JSON.stringify(e.args?.data ?? {}).slice(0, 160)}`);
    }
    const state = marks.filter(([ts]) => ts <= t.ts).pop()?.[1] ?? "?";
    out.push({
      at: (t.ts - t0us) / 1000,
      ms: t.dur / 1000,
      cpu: (t.tdur ?? NaN) / 1000,
      state,
      scripts: scripts.filter((e) => e.dur >= 1000).map(describe),
      phases,
      ...profileOf(t.ts, end),
    });
  }
  return { tasks: out, marks, cpuMax, totals };
}

/** Reads a Tracing stream (IO.read) into its events. */
async function readStream(cdp, handle) {
  const parts = [];
  for (;;) {
    const r = await cdp.send("IO.read", { handle, size: 1 << 22 });
    parts.push(r.base64Encoded ? Buffer.from(r.data, "base64").toString("utf8") : r.data);
    if (r.eof) break;
  }
  await cdp.send("IO.close", { handle });
  const json = JSON.parse(parts.join(""));
  return Array.isArray(json) ? json : json.traceEvents;
}

// ------------------------------------------------------------------ the runs
const env = await start();
try {
  for (const model of models) {
    for (let r = 0; r < runs; r++) {
      const { page, context } = await openPage(env.browser, env.url);
      try {
        // the page's state changes as user-timing marks, found in the trace
        await page.evaluate(() => {
          const mark = () => performance.mark(`dropslice:${document.body.dataset.state ?? ""}`);
          new MutationObserver(mark).observe(document.body, { attributes: true, attributeFilter: ["data-state"] });
        });
        await waitSettled(page); // the sample part
        // the trace from here on (the bench's observer counts what follows the sample part too)
        const cdp = trace ? await context.newCDPSession(page) : null;
        if (cdp) await cdp.send("Tracing.start", { transferMode: "ReturnAsStream", traceConfig: { includedCategories: CATEGORIES, recordMode: "recordAsMuchAsPossible" } });
        // as scripts/bench_table.mjs: long tasks and the longest gap of a 16 ms timer from here on
        await watchLongTasks(page);
        // the file chosen: a mark for the trace's clock, and the observer's time of it
        const chosenAt = await page.evaluate(() => {
          performance.mark("dropslice:chosen");
          return performance.now() - window.__longTasks.from;
        });
        await page.setInputFiles("#file-input", model);
        const s = await waitSettled(page, 900_000);
        const watched = await longTasks(page);
        const w = { tasks: watched.tasks.map(([t, d]) => [t - chosenAt, d]), gap: watched.gap };
        const name = model.split("/").pop();
        const over = w.tasks.filter(([, d]) => d > limit);
        const longest = w.tasks.reduce((m, [, d]) => Math.max(m, d), 0);
        console.log(`${name}, run ${r + 1}${trace ? " (traced)" : ""}: ${s.state} after ${s.seconds?.toFixed(2)} s, ${s.layers} layers, ${s.workers} workers; the observer: longest task ${longest.toFixed(0)} ms, ${over.length} over ${limit} ms; longest 16 ms timer gap ${w.gap.toFixed(0)} ms${over.length ? `; over ${limit} ms at ${over.map(([t, d]) => `${t.toFixed(0)} (${d.toFixed(0)})`).join(", ")} ms` : ""}`);
        if (!cdp) continue;
        const done = new Promise((ok) => cdp.once("Tracing.tracingComplete", ok));
        await cdp.send("Tracing.end");
        const { stream } = await done;
        const events = await readStream(cdp, stream);
        const chosen = events.find((e) => e.name === "dropslice:chosen");
        const watchMark = events.find((e) => e.name === "dropslice:watched");
        const { tasks, cpuMax, totals } = analyse(events, watchMark?.ts ?? 0, chosen?.ts ?? 0);
        const phaseText = (phases) => phases.map(([k, [w, c]]) => `${k} ${c.toFixed(1)} (${w.toFixed(1)})`).join(", ");
        console.log(`  the page's thread from the file chosen: ${totals.tasks} tasks, CPU ${totals.cpu.toFixed(0)} ms; phases, CPU (wall) ms: ${phaseText(totals.phases)}`);
        console.log(`    the page's own functions, all tasks: ${totals.own.map(([f, ms]) => `${f} ${ms.toFixed(0)}`).join("; ")}`);
        console.log(`  the trace: the longest task's CPU ${cpuMax.toFixed(1)} ms; ${tasks.length} tasks over ${limit} ms of wall time or ${cpuLimit} ms of CPU`);
        for (const t of tasks) {
          console.log(`  task at ${t.at.toFixed(0)} ms: ${t.ms.toFixed(1)} ms (its thread's CPU ${t.cpu.toFixed(1)} ms), state ${t.state}`);
          console.log(`    phases, CPU (wall) ms: ${phaseText(t.phases)}`);
          console.log(`    script: ${t.scripts.slice(0, 6).join("; ") || "none over 1 ms"}${t.scripts.length > 6 ? `; … ${t.scripts.length - 6} more` : ""}`);
          console.log("    self time:");
          for (const [f, ms] of t.self) console.log(`      ${ms.toFixed(1).padStart(6)} ms  ${f}`);
          console.log("    the page's own functions (innermost first, with what they called):");
          for (const [f, ms] of t.own) console.log(`      ${ms.toFixed(1).padStart(6)} ms  ${f}`);
        }
      } finally {
        await context.close();
      }
    }
  }
} finally {
  await env.close();
}

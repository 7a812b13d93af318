#!/usr/bin/env node
// Every repository path named in the docs and in code comments exists (run by `npm test`,
// scripts/test.sh; tested by tests/paths.test.mjs). Node only, no packages.
//
//   node scripts/check_paths.mjs [ROOT]      ROOT: the repository (default: this script's ../)
//
// Where it looks:
//   * docs/*.md and README.md, all of their text. CHANGELOG.md is left out on purpose: it is
//     history, and an entry may name a file that was later moved or removed.
//   * the comments of src/**/*.rs, www/**/*.ts (not www/pkg, which is generated),
//     scripts/* and tests/** (.rs, .ts, .mjs, .js, .py, .sh): `//`, `/* … */` and `#` lines.
// What counts as a path:
//   * `src/…`, `www/…`, `docs/…`, `scripts/…`, `tests/…`, `examples/…` ending in a file
//     extension or a slash (`src/model/mesh.rs`, `tests/e2e/`), relative to ROOT;
//   * a path whose first folder is one of src/'s or www/'s folders (`model/prepare.rs`,
//     `flows/slice.ts`, as docs/architecture.md writes them): it must exist under src/ or www/;
//   * in markdown, the target of a relative link `[text](images/x.svg)`, from the file's folder,
//     and a link's `#anchor` into a markdown file (the same one or another): one of its
//     headings must have that anchor, as GitHub makes them.
// A file whose text holds the words "check_paths: fixtures" (tests/paths.test.mjs, whose
// strings are made-up repositories) is not read.
// Paths under generated folders (target/, dist/, www/pkg/, node_modules/) and patterns (`*`,
// `{…}`, `NAME`-style placeholders in capitals) are not checked.
// Citations of docs/spec.md's sections: `docs/spec.md 5.3.2` needs a heading numbered 5.3.2
// (or a range such as 4.1–4.2 holding it), `docs/spec.md "Loop seams"` a heading that begins
// with those words. A citation of the old upper-case specification file, which is not in
// the repository, is reported: cite docs/spec.md.
// It prints each missing path or section with the file and line that names it and exits
// with 1.

import { existsSync, readdirSync, readFileSync, statSync } from "node:fs";
import { dirname, join, relative, resolve } from "node:path";
import { fileURLToPath } from "node:url";

const PREFIXES = ["src", "www", "docs", "scripts", "tests", "examples"];
const GENERATED = ["target/", "dist/", "www/pkg/", "node_modules/", "test-results/"];
const FIXTURES = ["check_paths", "fixtures"].join(": ");
const CODE_EXT = /\.(rs|ts|mjs|js|py|sh)$/;

/** Every file under `dir` (relative to `root`) whose name passes `keep`, skipping `skip` dirs. */
function walk(root, dir, keep, skip = []) {
  const out = [];
  const abs = join(root, dir);
  if (!existsSync(abs)) return out;
  for (const name of readdirSync(abs).sort()) {
    const rel = dir ? `${dir}/${name}` : name;
    const st = statSync(join(root, rel));
    if (st.isDirectory()) {
      if (!skip.includes(rel) && name !== "node_modules") out.push(...walk(root, rel, keep, skip));
    } else if (keep(name)) {
      out.push(rel);
    }
  }
  return out;
}

/** The comment text of each line of a code file (empty where a line has none). */
export function commentLines(text, file) {
  const hash = /\.(py|sh)$/.test(file) || !/\.[a-z]+$/.test(file);
  const lines = text.split("\n");
  const out = [];
  let inBlock = false;
  for (const line of lines) {
    if (hash) {
      const i = line.indexOf("#");
      out.push(i >= 0 ? line.slice(i + 1) : "");
      continue;
    }
    let comment = "";
    let rest = line;
    if (inBlock) {
      const end = rest.indexOf("*/");
      if (end < 0) {
        out.push(rest);
        continue;
      }
      comment += rest.slice(0, end) + " ";
      rest = rest.slice(end + 2);
      inBlock = false;
    }
    for (;;) {
      const line_ = rest.indexOf("//");
      const block = rest.indexOf("/*");
      if (line_ >= 0 && (block < 0 || line_ < block)) {
        comment += rest.slice(line_ + 2);
        break;
      }
      if (block < 0) break;
      const end = rest.indexOf("*/", block + 2);
      if (end < 0) {
        comment += rest.slice(block + 2);
        inBlock = true;
        break;
      }
      comment += rest.slice(block + 2, end) + " ";
      rest = rest.slice(end + 2);
    }
    out.push(comment);
  }
  return out;
}

// A path: not part of a longer word, URL or path before it; ends in a word character or "/".
const PATH = /(?<![\w./@~:-])((?:[\w-]+\/)+(?:[\w.-]*[\w])?\/?)/g;
const LINK = /\]\(([^)\s]+)(?:\s+"[^"]*")?\)/g;

/** A placeholder in capitals (`tests/NAME.rs`, `fixtures/oracle/NAME.json`), not a path. */
function isPlaceholder(p) {
  const word = (s) =>
    /^[A-Z][A-Z0-9_]+(\.[\w.]+)?$/.test(s) && !/^(README|CHANGELOG|LICENSE)\b/.test(s);
  return p.split("/").some(word);
}

/** The paths a line names that must exist: [{path, candidates}] (one candidate must exist). */
export function pathsIn(line, srcDirs) {
  const found = [];
  for (const m of line.matchAll(PATH)) {
    const p = m[1];
    const last = p.endsWith("/") ? "" : p.slice(p.lastIndexOf("/") + 1);
    const isFile = /\.[A-Za-z0-9]+$/.test(last);
    if (!(p.endsWith("/") || isFile)) continue;
    // A line number (":274") or a full stop after the path is not part of it; a pattern (`tests/e2e/*.test.mjs`,
    // `src/{a,b}.rs`) goes on after it with "*" or "{".
    if (isPlaceholder(p) || /^[*{<]/.test(line.slice(m.index + p.length))) continue;
    const dir = p.endsWith("/") ? p : `${p}/`;
    if (GENERATED.some((g) => dir.startsWith(g))) continue;
    const first = p.slice(0, p.indexOf("/"));
    if (PREFIXES.includes(first)) found.push({ path: p, candidates: [p] });
    else if (srcDirs.has(first)) {
      const c = [];
      for (const top of ["src", "www"]) if (srcDirs.get(first).includes(top)) c.push(`${top}/${p}`);
      found.push({ path: p, candidates: c });
    }
  }
  return found;
}

const CITE = /docs\/spec\.md(?:'s)?,?\s+(?:(\d+(?:\.\d+)*)|"([^"]+)")/g;
const OLD_SPEC = /(?<![\w/.-])SPEC\.md/g;

/** The headings of docs/spec.md: their numbers (a range's ends and what lies between) and texts. */
export function specHeadings(text) {
  const numbers = new Set();
  const titles = [];
  for (const line of text.split("\n")) {
    const h = /^#{1,6}\s+(.*)$/.exec(line);
    if (!h) continue;
    const title = h[1].trim();
    titles.push(title);
    const r = /^(\d+(?:\.\d+)*)(?:[–-](\d+(?:\.\d+)*))?\s/.exec(title);
    if (!r) continue;
    numbers.add(r[1]);
    if (r[2]) {
      // 4.1–4.2: every number from the first to the last in its last place.
      const a = r[1].split("."), b = r[2].split(".");
      const head = a.slice(0, -1).join(".");
      for (let i = Number(a.at(-1)); i <= Number(b.at(-1)); i++)
        numbers.add(head ? `${head}.${i}` : String(i));
    }
  }
  return { numbers, titles };
}

/** The docs/spec.md sections a line cites that have no heading, and citations of the old file. */
export function badCitations(line, headings) {
  const bad = [];
  for (const m of line.matchAll(CITE)) {
    if (m[1] !== undefined && !headings.numbers.has(m[1])) bad.push(`docs/spec.md ${m[1]}`);
    if (m[2] !== undefined && !headings.titles.some((t) => t.startsWith(m[2])))
      bad.push(`docs/spec.md "${m[2]}"`);
  }
  for (const _ of line.matchAll(OLD_SPEC)) bad.push("SPEC.md (not in the repository: cite docs/spec.md)");
  return bad;
}

/** Relative link targets of a markdown line: [{path, candidates}] resolved from `dir`. */
export function linksIn(line, dir, file) {
  const found = [];
  for (const m of line.matchAll(LINK)) {
    const raw = m[1].replace(/^<|>$/g, "");
    if (/^[a-z][a-z0-9+.-]*:/i.test(raw) || raw.startsWith("/")) continue;
    const [target, anchor] = raw.split("?")[0].split("#");
    const t = decodeURIComponent(target);
    const p = t ? join(dir, t).replaceAll("\\", "/") : file;
    if (p.startsWith("..")) continue; // outside the repository
    found.push({ path: t || raw, candidates: [p], anchor: anchor ? decodeURIComponent(anchor) : "" });
  }
  return found;
}

/** The anchors of a markdown file's headings, as GitHub makes them ("4.5 Machine code" → "45-machine-code"). */
export function anchors(text) {
  const seen = new Map();
  const out = new Set();
  let fence = false;
  for (const line of text.split("\n")) {
    if (/^\s*```/.test(line)) fence = !fence;
    const h = !fence && /^#{1,6}\s+(.*?)\s*#*\s*$/.exec(line);
    if (!h) continue;
    const base = h[1]
      .toLowerCase()
      .replace(/[^\p{L}\p{N}\s_-]/gu, "")
      .replace(/\s/g, "-");
    const n = seen.get(base) ?? 0;
    seen.set(base, n + 1);
    out.add(n ? `${base}-${n}` : base);
  }
  return out;
}

/** The missing paths of the repository at `root`: [{file, line, path}]. */
export function check(root) {
  const srcDirs = new Map();
  for (const top of ["src", "www"]) {
    const abs = join(root, top);
    if (!existsSync(abs)) continue;
    for (const name of readdirSync(abs)) {
      if (`${top}/${name}` === "www/pkg" || !statSync(join(abs, name)).isDirectory()) continue;
      srcDirs.set(name, [...(srcDirs.get(name) ?? []), top]);
    }
  }
  const docs = [
    ...walk(root, "docs", (n) => n.endsWith(".md")).filter((f) => f.split("/").length === 2),
    ...(existsSync(join(root, "README.md")) ? ["README.md"] : []),
  ];
  const code = [
    ...walk(root, "src", (n) => n.endsWith(".rs")),
    ...walk(root, "www", (n) => n.endsWith(".ts"), ["www/pkg"]),
    ...walk(root, "scripts", (n) => CODE_EXT.test(n) || !n.includes(".")),
    ...walk(root, "tests", (n) => CODE_EXT.test(n), ["tests/fixtures"]),
  ];
  const missing = [];
  const exists = (p) => existsSync(join(root, p));
  const report = (file, i, found) => {
    for (const { path, candidates } of found)
      if (!candidates.some(exists)) missing.push({ file, line: i + 1, path });
  };
  const specPath = join(root, "docs", "spec.md");
  const headings = specHeadings(existsSync(specPath) ? readFileSync(specPath, "utf8") : "");
  const cite = (file, i, line) => {
    for (const path of badCitations(line, headings)) missing.push({ file, line: i + 1, path });
  };
  for (const file of docs) {
    const lines = readFileSync(join(root, file), "utf8").split("\n");
    let fence = false;
    lines.forEach((line, i) => {
      if (/^\s*```/.test(line)) fence = !fence;
      report(file, i, pathsIn(line, srcDirs));
      cite(file, i, line);
      if (fence) return;
      const links = linksIn(line, dirname(file), file);
      report(file, i, links);
      for (const { path, candidates, anchor } of links) {
        const target = candidates[0];
        if (!anchor || !target.endsWith(".md") || !exists(target)) continue;
        if (!anchors(readFileSync(join(root, target), "utf8")).has(anchor))
          missing.push({ file, line: i + 1, path: `${path.split("#")[0]}#${anchor} (no such heading)` });
      }
    });
  }
  for (const file of code) {
    const text = readFileSync(join(root, file), "utf8");
    if (text.includes(FIXTURES)) continue;
    commentLines(text, file).forEach((c, i) => {
      report(file, i, pathsIn(c, srcDirs));
      cite(file, i, c);
    });
  }
  return missing;
}

const self = fileURLToPath(import.meta.url);
if (process.argv[1] && resolve(process.argv[1]) === self) {
  const root = resolve(process.argv[2] ?? join(dirname(self), ".."));
  const missing = check(root);
  if (missing.length) {
    console.error(
      `${missing.length} path(s) or section(s) named in docs or comments do not exist (under ${relative(process.cwd(), root) || "."}):`,
    );
    for (const m of missing) console.error(`  ${m.file}:${m.line}: ${m.path}`);
    console.error("Fix the path (where did the file go?) or, if it is not a path of this repository, write it so it is not read as one.");
    process.exit(1);
  }
  console.log("every path named in docs and comments exists");
}

// scripts/check_paths.mjs on small repositories made here: it names every missing path (full
// form, a folder of src/ or www/ as docs/architecture.md writes it, a markdown link, code
// comments) with its file and line, and passes a repository whose paths all exist.
// check_paths: fixtures (the strings below are made-up repositories, not this one's paths)
import { test } from "node:test";
import assert from "node:assert/strict";
import { execFileSync, spawnSync } from "node:child_process";
import { mkdtempSync, mkdirSync, rmSync, writeFileSync } from "node:fs";
import { tmpdir } from "node:os";
import { dirname, join } from "node:path";
import { fileURLToPath } from "node:url";

const script = join(dirname(fileURLToPath(import.meta.url)), "..", "scripts", "check_paths.mjs");

/** A repository of `files` ({path: text}) in a temporary folder; removed after `body`. */
function withRepo(files, body) {
  const root = mkdtempSync(join(tmpdir(), "check-paths-"));
  try {
    for (const [path, text] of Object.entries(files)) {
      mkdirSync(dirname(join(root, path)), { recursive: true });
      writeFileSync(join(root, path), text);
    }
    return body(root);
  } finally {
    rmSync(root, { recursive: true, force: true });
  }
}

const good = {
  "tests/skipped.rs": "// check_paths: fixtures\n// src/not-checked.rs\n",
  "src/model/mesh.rs":
    "//! The mesh (docs/spec.md 5.3.1; tests/a.rs), docs/spec.md 4.2, docs/spec.md's \"Loop seams\".\nfn f() {}\n",
  "src/lib.rs": "/* see src/model/mesh.rs\n   and model/mesh.rs */\nlet url = \"https://x.org/src/gone.rs\";\n",
  "www/core/job.ts": "// The job (src/model/, www/flows/open.ts, tests/e2e/*.test.mjs, tests/NAME.rs)\n",
  "www/flows/open.ts": "export {};\n",
  "www/pkg/x.d.ts": "// generated: src/nothing.rs is not read here\n",
  "tests/a.rs": "// tests/fixtures/oracle/NAME.json, www/pkg/dropslice.d.ts (generated), dist/worker.js\n",
  "scripts/test.sh": "#!/bin/sh\n# runs scripts/test.sh and node tests/a.rs\necho src/in-code-not-a-comment.rs\n",
  "docs/spec.md":
    "# Spec\n`model/mesh.rs`, `core/job.ts`, [the page](../README.md), ![a](images/a.svg), [b](#spec), [c](https://e.org/y.md)\n" +
    "## 4.1–4.2 The machine\n### 5.3.1 Import\n## Loop seams (`loop_spacing`)\nSee docs/spec.md 4.1.\n",
  "docs/images/a.svg": "<svg/>",
  "README.md": "# Readme\nSee [docs/spec.md](docs/spec.md#loop-seams-loop_spacing), [the tests](#readme) and `src/model/mesh.rs:12`.\n",
  "CHANGELOG.md": "- removed src/old.rs (history is not checked)\n",
};

test("a repository whose named paths all exist passes", () => {
  withRepo(good, (root) => {
    const out = execFileSync("node", [script, root], { encoding: "utf8" });
    assert.match(out, /every path named in docs and comments exists/);
  });
});

test("every missing path is named with its file and line, and the check fails", () => {
  const bad = {
    ...good,
    "src/lib.rs": "fn a() {}\n// moved: src/budget.rs\n// SPEC.md 5.3.1, docs/spec.md 5.3.2, docs/spec.md \"Seams\"\n",
    "www/core/job.ts": "/**\n * The worker (www/worker.ts).\n */\n",
    "scripts/test.sh": "#!/bin/sh\n# runs tests/gone.test.mjs\n",
    "docs/spec.md":
      "# Spec\n\n| stage | `model/prepare.rs` |\n[x](missing.md) ![y](images/b.svg)\n### 5.3.1 Import\n## 4.1–4.2 The machine\n## Loop seams\n" +
      "[m](#4142-the-machine) [n](#nowhere) [o](../README.md#readme) [p](../README.md#gone)\n",
    "README.md": "# Readme\nSee docs/nothing.md.\n",
  };
  withRepo(bad, (root) => {
    const r = spawnSync("node", [script, root], { encoding: "utf8" });
    assert.equal(r.status, 1, r.stdout + r.stderr);
    const lines = r.stderr.split("\n").filter((l) => l.startsWith("  ")).map((l) => l.trim());
    assert.deepEqual(lines.sort(), [
      "README.md:2: docs/nothing.md",
      "docs/spec.md:8: #nowhere (no such heading)",
      "docs/spec.md:8: ../README.md#gone (no such heading)",
      "docs/spec.md:3: model/prepare.rs",
      "docs/spec.md:4: images/b.svg",
      "docs/spec.md:4: missing.md",
      "scripts/test.sh:2: tests/gone.test.mjs",
      "src/lib.rs:2: src/budget.rs",
      "src/lib.rs:3: SPEC.md (not in the repository: cite docs/spec.md)",
      "src/lib.rs:3: docs/spec.md \"Seams\"",
      "src/lib.rs:3: docs/spec.md 5.3.2",
      "www/core/job.ts:2: www/worker.ts",
    ].sort());
    assert.match(r.stderr, /^12 path\(s\) or section\(s\) named in docs or comments do not exist/);
  });
});

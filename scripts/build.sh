#!/usr/bin/env bash
# Builds the page into dist/: the core for wasm32 (release), its wasm-bindgen glue, a type
# check of www/, and the esbuild bundles (page + worker).
set -euo pipefail
cd "$(dirname "$0")/.."

echo "== wasm: cargo build --target wasm32-unknown-unknown" >&2
cargo build --release --target wasm32-unknown-unknown --lib
rm -rf www/pkg
wasm-bindgen --target web --out-dir www/pkg --out-name dropslice \
  target/wasm32-unknown-unknown/release/dropslice.wasm

echo "== typescript: tsc --noEmit" >&2
node_modules/.bin/tsc --noEmit -p www

echo "== bundle: esbuild" >&2
rm -rf dist
mkdir -p dist
node_modules/.bin/esbuild www/main.ts www/worker.ts --bundle --format=esm --target=es2022 \
  --minify --sourcemap --outdir=dist --log-level=warning
cp www/index.html www/style.css dist/
# No wasm-opt: Debian's binaryen 108 produced a module whose function table Chromium rejects
# ("WebAssembly.Table.set(): Argument 1 is invalid"); rustc's release output is small enough.
cp www/pkg/dropslice_bg.wasm dist/
echo "== built dist/ ($(du -sh dist | cut -f1))" >&2

#!/usr/bin/env bash
# Builds the page into dist/: the core for wasm32 (release), its wasm-bindgen glue, a type
# check of www/, the esbuild bundles (page + worker), the manifest and icons, and the service
# worker (offline use) with the build's id.
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
cp www/manifest.webmanifest dist/
mkdir -p dist/icons
cp www/icons/icon.svg www/icons/icon-192.png www/icons/icon-512.png dist/icons/
# The service worker last: its cache is named after a hash of the app shell it precaches
# (www/sw.ts SHELL), so a build that changes any of them is a new cache and a new sw.js.
build_id=$(cd dist && cat index.html main.js worker.js style.css dropslice_bg.wasm \
  manifest.webmanifest icons/icon.svg icons/icon-192.png icons/icon-512.png | sha256sum | cut -c1-16)
node_modules/.bin/esbuild www/sw.ts --bundle --format=iife --target=es2022 --minify \
  "--define:BUILD_ID=\"$build_id\"" --outfile=dist/sw.js --log-level=warning
echo "== build id $build_id" >&2
echo "== built dist/ ($(du -sh dist | cut -f1))" >&2

#!/usr/bin/env bash
# Builds the page into dist/: the core for wasm32 (release), its wasm-bindgen glue, a type
# check of www/, the esbuild bundles (the page, www/main.ts; the worker, www/worker/worker.ts),
# the manifest and icons, and the service worker (offline use, www/pwa/sw.ts) with the build's id.
set -euo pipefail
cd "$(dirname "$0")/.."

# WebAssembly SIMD (every current browser has it): the loops that vectorise use it. Only the
# wasm32 build gets the flag (the native build and the tests are untouched).
echo "== wasm: cargo build --target wasm32-unknown-unknown (+simd128)" >&2
CARGO_TARGET_WASM32_UNKNOWN_UNKNOWN_RUSTFLAGS="-C target-feature=+simd128" \
  cargo build --release --target wasm32-unknown-unknown --lib
rm -rf www/pkg
wasm-bindgen --target web --out-dir www/pkg --out-name dropslice \
  target/wasm32-unknown-unknown/release/dropslice.wasm
# wasm-opt -O3 from the `binaryen` npm package (package-lock.json pins it; it runs without
# downloading anything). Debian's binaryen 108 produced a module whose function table
# Chromium rejects; the page's tests check the optimised module. The features are the ones
# rustc's wasm32 target enables, and SIMD. WASM_OPT names another wasm-opt.
wasm_opt="${WASM_OPT:-node_modules/binaryen/bin/wasm-opt}"
if [ -x "$wasm_opt" ]; then
  echo "== wasm-opt -O3 ($("$wasm_opt" --version))" >&2
  "$wasm_opt" -O3 --enable-bulk-memory --enable-nontrapping-float-to-int --enable-sign-ext \
    --enable-mutable-globals --enable-reference-types --enable-multivalue --enable-simd \
    www/pkg/dropslice_bg.wasm -o www/pkg/dropslice_bg.opt.wasm
  mv www/pkg/dropslice_bg.opt.wasm www/pkg/dropslice_bg.wasm
else
  echo "== wasm-opt skipped: $wasm_opt is missing (npm run setup installs binaryen)" >&2
fi

echo "== typescript: tsc --noEmit" >&2
node_modules/.bin/tsc --noEmit -p www

echo "== bundle: esbuild" >&2
rm -rf dist
mkdir -p dist
# The page: split (format esm), so the code that only the 3D tab needs (three.js: the bulk of
# the script) is a chunk of its own, loaded by a dynamic import() when the tab is first opened;
# code both share goes into chunks too. Chunks sit beside main.js (dist/NAME-HASH.js), so
# URLs made from import.meta.url (the worker's) mean the same in any of them. The worker is
# bundled alone, unsplit: one file.
node_modules/.bin/esbuild www/main.ts --bundle --splitting --format=esm --target=es2022 \
  --minify --sourcemap --outdir=dist --log-level=warning
node_modules/.bin/esbuild www/worker/worker.ts --bundle --format=esm --target=es2022 \
  --minify --sourcemap --outdir=dist --log-level=warning
cp www/index.html www/style.css dist/
cp www/pkg/dropslice_bg.wasm dist/
cp www/manifest.webmanifest dist/
mkdir -p dist/icons
cp www/icons/icon.svg www/icons/icon-192.png www/icons/icon-512.png dist/icons/
# The service worker last. It precaches the app shell: every file in dist/ but source maps
# (the chunks' names change with their content, so the list is made here, from the listing,
# and injected as SHELL). Its cache is named after a hash of those files (BUILD_ID), so a
# build that changes any of them is a new cache and a new sw.js.
mapfile -t shell < <(cd dist && find . -type f ! -name '*.map' -printf '%P\n' | LC_ALL=C sort)
shell_json=$(printf '%s\n' "${shell[@]}" | node -e \
  'process.stdout.write(JSON.stringify(require("fs").readFileSync(0, "utf8").split("\n").filter(Boolean)))')
for f in index.html main.js worker.js dropslice_bg.wasm; do
  [[ " ${shell[*]} " == *" $f "* ]] || { echo "build: dist/$f is missing from the shell" >&2; exit 1; }
done
build_id=$(cd dist && cat "${shell[@]}" | sha256sum | cut -c1-16)
node_modules/.bin/esbuild www/pwa/sw.ts --bundle --format=iife --target=es2022 --minify \
  "--define:BUILD_ID=\"$build_id\"" "--define:SHELL=$shell_json" --outfile=dist/sw.js --log-level=warning
echo "== build id $build_id" >&2
echo "== built dist/ ($(du -sh dist | cut -f1))" >&2

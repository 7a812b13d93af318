#!/usr/bin/env bash
# Installs what building and testing need, skipping whatever is already there (idempotent):
# the wasm32 target, wasm-bindgen-cli 0.2.130 (must equal the wasm-bindgen crate's version),
# Debian's Chromium for the browser tests, and the npm packages of package-lock.json.
set -euo pipefail
cd "$(dirname "$0")/.."

WASM_BINDGEN_VERSION=0.2.130
SUDO=""
if [ "$(id -u)" != 0 ] && command -v sudo >/dev/null; then SUDO=sudo; fi

if ! rustup target list --installed 2>/dev/null | grep -qx wasm32-unknown-unknown; then
  echo "setup: rustup target add wasm32-unknown-unknown" >&2
  rustup target add wasm32-unknown-unknown
fi

if [ "$(wasm-bindgen --version 2>/dev/null || true)" != "wasm-bindgen $WASM_BINDGEN_VERSION" ]; then
  # without --locked: one dependency locked by the CLI's lockfile is missing from the registry
  echo "setup: cargo install wasm-bindgen-cli $WASM_BINDGEN_VERSION (takes ~4 minutes)" >&2
  cargo install wasm-bindgen-cli --version "$WASM_BINDGEN_VERSION" --force
fi

if [ ! -x /usr/bin/chromium ]; then
  echo "setup: apt-get install chromium" >&2
  $SUDO apt-get update
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y chromium
fi

# npm writes node_modules/.package-lock.json on every install: missing or older than
# package-lock.json means node_modules is absent, incomplete or stale.
if [ ! -f node_modules/.package-lock.json ] || [ package-lock.json -nt node_modules/.package-lock.json ] \
   || [ ! -e node_modules/.bin/esbuild ] || [ ! -e node_modules/.bin/tsc ] || [ ! -d node_modules/playwright-core ]; then
  echo "setup: npm ci" >&2
  npm ci --no-audit --no-fund
fi

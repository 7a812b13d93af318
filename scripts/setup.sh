#!/usr/bin/env bash
# Installs what building and testing need, skipping whatever is already there (idempotent):
#   1. the wasm32-unknown-unknown Rust target (rustup)
#   2. wasm-bindgen-cli 0.2.130 (must equal the wasm-bindgen crate's version; also brings
#      wasm-bindgen-test-runner), compiled from source with cargo
#   3. wasm-pack 0.15.1, compiled from source with cargo (its npm wrapper downloads a binary)
#   4. Debian's Chromium for the browser tests
#   5. the oracle's Python packages (numpy, shapely) in a project-local virtual environment,
#      target/pyenv, which the tests use whatever python3 is first on PATH
#   6. the npm packages of package-lock.json
# scripts/check_tools.sh checks afterwards that each of them is there.
set -euo pipefail
cd "$(dirname "$0")/.."

WASM_BINDGEN_VERSION=0.2.130
WASM_PACK_VERSION=0.15.1
NUMPY_VERSION=2.4.6
SHAPELY_VERSION=2.2.0
PYENV_DIR=target/pyenv
SUDO=""
if [ "$(id -u)" != 0 ] && command -v sudo >/dev/null; then SUDO=sudo; fi
export PATH="$HOME/.cargo/bin:$PATH"

apt_updated=""
apt_install() {
  if [ -z "$apt_updated" ]; then $SUDO apt-get update; apt_updated=1; fi
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y "$@"
}

if ! rustup target list --installed 2>/dev/null | grep -qx wasm32-unknown-unknown; then
  echo "setup: rustup target add wasm32-unknown-unknown" >&2
  rustup target add wasm32-unknown-unknown
fi

if [ "$(wasm-bindgen --version 2>/dev/null || true)" != "wasm-bindgen $WASM_BINDGEN_VERSION" ] \
   || ! command -v wasm-bindgen-test-runner >/dev/null; then
  # without --locked: one dependency locked by the CLI's lockfile is missing from the registry
  echo "setup: cargo install wasm-bindgen-cli $WASM_BINDGEN_VERSION (takes ~4 minutes)" >&2
  cargo install wasm-bindgen-cli --version "$WASM_BINDGEN_VERSION" --force
fi

if [ "$(wasm-pack --version 2>/dev/null || true)" != "wasm-pack $WASM_PACK_VERSION" ]; then
  echo "setup: cargo install wasm-pack $WASM_PACK_VERSION (takes ~3 minutes)" >&2
  cargo install wasm-pack --version "$WASM_PACK_VERSION" --locked --force
fi

if [ ! -x /usr/bin/chromium ]; then
  echo "setup: apt-get install chromium" >&2
  apt_install chromium
fi

# The oracle (../shared/tools/oracle_sections.py) needs numpy and shapely. They go into a
# virtual environment of the project's own, so neither the machine's Python nor its
# packages matter; tests/common finds target/pyenv/bin/python3 (ORACLE_PYTHON overrides it).
if ! "$PYENV_DIR/bin/python3" -c "import numpy, shapely" 2>/dev/null; then
  echo "setup: python3 -m venv $PYENV_DIR; pip install numpy==$NUMPY_VERSION shapely==$SHAPELY_VERSION" >&2
  rm -rf "$PYENV_DIR"
  if ! python3 -m venv "$PYENV_DIR"; then
    # Debian's python3 keeps venv (ensurepip) in a package of its own
    rm -rf "$PYENV_DIR"
    apt_install python3-venv
    python3 -m venv "$PYENV_DIR"
  fi
  "$PYENV_DIR/bin/python3" -m pip install --quiet --disable-pip-version-check \
    "numpy==$NUMPY_VERSION" "shapely==$SHAPELY_VERSION"
fi

# npm writes node_modules/.package-lock.json on every install: missing or older than
# package-lock.json means node_modules is absent, incomplete or stale.
if [ ! -f node_modules/.package-lock.json ] || [ package-lock.json -nt node_modules/.package-lock.json ] \
   || [ ! -e node_modules/.bin/esbuild ] || [ ! -e node_modules/.bin/tsc ] || [ ! -d node_modules/playwright-core ] \
   || [ ! -e node_modules/.bin/wasm-opt ]; then
  echo "setup: npm ci" >&2
  npm ci --no-audit --no-fund
fi

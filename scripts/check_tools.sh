#!/usr/bin/env bash
# Checks, before any test runs, that every tool and package the tests call is present, and
# names the missing ones with the step of scripts/setup.sh that installs each. Exit 1 if any
# is missing (run `bash scripts/setup.sh`, or `npm test`, which runs it first).
set -uo pipefail
cd "$(dirname "$0")/.."
export PATH="$HOME/.cargo/bin:$PATH"
missing=()
need() { # need DESCRIPTION SETUP_STEP COMMAND...
  local what=$1 step=$2; shift 2
  "$@" >/dev/null 2>&1 || missing+=("$what — setup step: $step")
}
version_is() { [ "$("$1" --version 2>/dev/null)" = "$2" ]; }

need "cargo (Rust toolchain)" "none: the base image's rustup toolchain" command -v cargo
need "rustfmt and clippy" "none: rustup component add rustfmt clippy" cargo clippy --version
need "cargo fmt" "none: rustup component add rustfmt" cargo fmt --version
need "the wasm32-unknown-unknown target" "1, rustup target add wasm32-unknown-unknown" \
  bash -c 'rustup target list --installed | grep -qx wasm32-unknown-unknown'
need "wasm-bindgen 0.2.130" "2, cargo install wasm-bindgen-cli --version 0.2.130" \
  version_is wasm-bindgen "wasm-bindgen 0.2.130"
need "wasm-bindgen-test-runner" "2, cargo install wasm-bindgen-cli --version 0.2.130" \
  command -v wasm-bindgen-test-runner
need "wasm-pack 0.15.1" "3, cargo install wasm-pack --version 0.15.1 --locked" \
  version_is wasm-pack "wasm-pack 0.15.1"
need "node (20 or newer)" "none: the base image's Node.js" \
  node -e 'process.exit(+process.versions.node.split(".")[0] >= 20 ? 0 : 1)'
need "Chromium at /usr/bin/chromium" "4, apt-get install chromium" test -x /usr/bin/chromium
need "the oracle's Python with numpy and shapely (target/pyenv)" \
  "5, python3 -m venv target/pyenv && target/pyenv/bin/pip install numpy==2.4.6 shapely==2.2.0" \
  "${ORACLE_PYTHON:-target/pyenv/bin/python3}" -c 'import numpy, shapely'
for bin in esbuild tsc wasm-opt; do
  need "node_modules/.bin/$bin" "6, npm ci" test -x "node_modules/.bin/$bin"
done
need "node_modules/playwright-core" "6, npm ci" test -d node_modules/playwright-core
need "node_modules/three" "6, npm ci" test -d node_modules/three
need "../shared beside the project (the models, the oracle, the checks)" \
  "none: clone the project next to shared/" test -f ../shared/tools/oracle_sections.py

if [ ${#missing[@]} -gt 0 ]; then
  echo "check_tools: the tests need what is not installed:" >&2
  for m in "${missing[@]}"; do echo "  - $m" >&2; done
  echo "Run: bash scripts/setup.sh" >&2
  exit 1
fi
echo "check_tools: every tool and package the tests call is present" >&2

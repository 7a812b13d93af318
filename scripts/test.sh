#!/usr/bin/env bash
# Everything CI runs (npm test, .ci/run): setup, format and lint checks, the native core tests,
# the wasm facade tests in Node, the page build and the browser end-to-end tests.
set -euo pipefail
cd "$(dirname "$0")/.."
step() { echo; echo "=== $* ($(date +%T))" >&2; }

step setup
bash scripts/setup.sh
export PATH="$HOME/.cargo/bin:$PATH"

step "every tool and package the tests call is present"
bash scripts/check_tools.sh

step "import cycles between top-level parts of src/ and www/ (deps.py)"
python3 ../shared/checks/deps.py

step "every path named in docs and comments exists"
node scripts/check_paths.mjs
node --test tests/paths.test.mjs

step "cargo fmt --check"
cargo fmt --check

step "cargo clippy"
cargo clippy --all-targets -- -D warnings
cargo clippy --target wasm32-unknown-unknown --lib --test wasm_session -- -D warnings

step "cargo test --release (native)"
cargo test --release

step "wasm facade tests (wasm-pack test --node --release)"
wasm-pack test --node --release

step "build the page"
bash scripts/build.sh

step "CLI for the comparison"
cargo build --release --bin dropslice

step "browser end-to-end tests (Chromium)"
node --test --test-concurrency=1 tests/e2e/
echo; echo "all tests passed" >&2

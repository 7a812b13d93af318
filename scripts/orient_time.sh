#!/usr/bin/env bash
# Speed target of the orientation (issue 26, docs/process.md): well under a second for
# 3DBenchy's 225k facets. Builds the example in release, runs it natively and fails when the
# median evaluation (file reading excluded) takes 1 s or more.
#
#   bash scripts/orient_time.sh [MODEL]   (default: ../shared/models/3DBenchy.stl)
set -euo pipefail
cd "$(dirname "$0")/.."
model="${1:-../shared/models/3DBenchy.stl}"
cargo build --release --example orient_time -q
line=$(target/release/examples/orient_time "$model" 7 2>&1 >/dev/null)
echo "$line"
ms=$(sed -E 's/.*median ([0-9.]+) ms.*/\1/' <<<"$line")
awk -v ms="$ms" 'BEGIN { if (ms >= 1000) { print "orient_time: over the 1 s target"; exit 1 } else { print "orient_time: within the 1 s target" } }'

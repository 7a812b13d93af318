#!/usr/bin/env bash
# Times the analysis natively: `dropslice MODEL -o X.gco` with and without `--report`, runs
# interleaved, best of N (wall and user+system CPU seconds). The analysis' cost is the
# difference. Usage:
#   bash scripts/analysis_time.sh [RUNS] [BINARY ...]     (default: 5, target/release/dropslice)
#   MODELS="3DBenchy extruder_idler" bash scripts/analysis_time.sh 3 old/dropslice new/dropslice
# Models from ../shared/models (MODELS: names without .stl). Prints a Markdown table and the
# 1-minute load before and after (the machine may be shared: compare binaries run together).
set -euo pipefail
cd "$(dirname "$0")/.."
runs="${1:-5}"
shift || true
bins=("$@")
[ ${#bins[@]} -gt 0 ] || bins=(target/release/dropslice)
models="${MODELS:-3DBenchy extruder_idler stanford_bunny esca_nonmanifold}"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
load() { cut -d' ' -f1 /proc/loadavg; }
echo "load before: $(load)"
echo
echo "| model | binary | slicing wall s | slicing CPU s | with --report wall s | with --report CPU s | analysis wall s | analysis CPU s |"
echo "|---|---|---:|---:|---:|---:|---:|---:|"
for m in $models; do
  f="../shared/models/$m.stl"
  [ -f "$f" ] || { echo "missing $f" >&2; exit 1; }
  # The bunny is wider than the default plate (154 × 134 mm): sliced as it is.
  extra=()
  [ "$m" = stanford_bunny ] && extra=(--set allow_off_plate=true)
  for b in "${bins[@]}"; do : >"$tmp/$(echo "$b" | tr '/' '_')_$m"; done
  for ((i = 0; i < runs; i++)); do
    for b in "${bins[@]}"; do
      key="$tmp/$(echo "$b" | tr '/' '_')_$m"
      /usr/bin/time -f "plain %e %U %S" -a -o "$key" "$b" -q "$f" -o "$tmp/x.gco" "${extra[@]}" 2>/dev/null
      /usr/bin/time -f "report %e %U %S" -a -o "$key" "$b" -q "$f" -o "$tmp/x.gco" --report "$tmp/x.json" "${extra[@]}" 2>/dev/null
    done
  done
  for b in "${bins[@]}"; do
    key="$tmp/$(echo "$b" | tr '/' '_')_$m"
    python3 - "$key" "$m" "$b" <<'P'
import sys
rows = [l.split() for l in open(sys.argv[1]) if l.split() and l.split()[0] in ("plain", "report")]
def best(kind):
    r = [(float(w), float(u) + float(s)) for k, w, u, s in rows if k == kind]
    return min(x[0] for x in r), min(x[1] for x in r)
(pw, pc), (rw, rc) = best("plain"), best("report")
print(f"| {sys.argv[2]} | {sys.argv[3]} | {pw:.2f} | {pc:.2f} | {rw:.2f} | {rc:.2f} | {rw - pw:.2f} | {rc - pc:.2f} |")
P
  done
done
echo
echo "load after: $(load)"

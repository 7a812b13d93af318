#!/usr/bin/env bash
# Benchmark of the dropslice CLI against CuraEngine 4.13 and PrusaSlicer 2.5 (issue 5).
#
#   bash scripts/bench.sh            (or: npm run bench:models; `npm run bench` is the short
#                                     table of scripts/bench_table.mjs)
#
# What it does
#   1. builds the release CLI (cargo build --release --bin dropslice);
#   2. installs the peers if missing (Debian: cura-engine, prusa-slicer, time; Cura's
#      machine definitions are unpacked from the `cura` package, as shared/bench/peers.sh
#      does) - skipped with BENCH_PEERS=0;
#   3. generates tori with shared/tools/gen_mesh.py (100k, 1M, 4M facets) and a copy of
#      the 1M torus stretched 4x in z (30 -> 120 mm, 150 -> 600 layers) into the cache
#      directory (reused on later runs);
#   4. per model and tool: one untimed warm-up run, then BENCH_RUNS timed runs (interleaved
#      across the tools) under
#      /usr/bin/time -v (wall time, peak RSS); the peers use the exact command lines of
#      shared/bench/peers.sh (its run_cura / run_prusa / layers_of functions are read
#      from that file, not copied);
#   5. prints the table (median wall time, peak RSS, dropslice/peer ratios) and the
#      target checks (scripts/bench_report.py); raw data in $BENCH_DIR/raw.tsv.
#
# Environment
#   BENCH_MODELS   space-separated model names or paths (default: every shared model and
#                  torus_100000 torus_1000000 torus_4000000 torus_1000000_z4); a name is
#                  looked up in $SHARED/models/NAME.stl, then as a generated torus
#                  (torus_N or torus_N_z4)
#   BENCH_TOOLS    default "dropslice cura prusa"
#   BENCH_PEERS    1 (default) or 0: 0 = dropslice only, no peer install
#   BENCH_PEER_SKIP  models the peers are not run on (default "torus_4000000
#                  torus_1000000_z4": their targets concern dropslice alone, and the peers
#                  need ~1-2 min per run there; set BENCH_PEER_SKIP= to include them)
#   BENCH_RUNS     timed runs per model and tool (default 3)
#   BENCH_WARMUP   untimed runs before them (default 1)
#   BENCH_TIMEOUT  seconds per run (default 900)
#   BENCH_DIR      cache and output directory (default target/bench)
#   BENCH_BROWSER  1: also time the web page (headless Chromium) on 3DBenchy and the
#                  1M torus, using the helpers in tests/e2e/helpers.mjs (default 0)
#   BENCH_DS_ARGS  extra arguments for dropslice (e.g. "--set fill_density=0.5")
#   DROPSLICE_SHARED  the shared directory (default ../shared next to the repo)
#
# Settings: dropslice runs with its defaults (layer 0.2 mm, 2 contours, 100 % fill,
# droplet width B = 1.04 x 0.2 = 0.208 mm); the peers with peers.sh's matched FDM
# settings (layer 0.2 mm, 2 walls, 100 % infill, 0.4 mm lines).  Same layers, but
# dropslice lays about twice as many lines per layer (0.208 vs 0.4 mm spacing).
set -uo pipefail
ROOT="$(cd "$(dirname "$0")/.." && pwd)"
cd "$ROOT"
SHARED="$(cd "${DROPSLICE_SHARED:-$ROOT/../shared}" && pwd)" || { echo "no shared dir" >&2; exit 1; }
BENCH_DIR="${BENCH_DIR:-$ROOT/target/bench}"
RUNS="${BENCH_RUNS:-3}"
WARMUP="${BENCH_WARMUP:-1}"
TIMEOUT="${BENCH_TIMEOUT:-900}"
PEERS="${BENCH_PEERS:-1}"
TOOLS="${BENCH_TOOLS:-dropslice cura prusa}"
[ "$PEERS" = 0 ] && TOOLS="dropslice"
DS_ARGS="${BENCH_DS_ARGS:-}"
PEER_SKIP="${BENCH_PEER_SKIP-torus_4000000 torus_1000000_z4}"
PEERS_SH="$SHARED/bench/peers.sh"
mkdir -p "$BENCH_DIR/models" "$BENCH_DIR/gcode" "$BENCH_DIR/logs"
log() { echo "[bench $(date +%T)] $*" >&2; }
SUDO=""; [ "$(id -u)" = 0 ] || SUDO="sudo"

# ------------------------------------------------------------------ 1. build
log "cargo build --release --bin dropslice"
cargo build --release --bin dropslice >&2 || { echo "build failed" >&2; exit 1; }
# A private copy: another build of target/release during the run must not change the binary.
mkdir -p "$BENCH_DIR/bin"
cp -f "$ROOT/target/release/dropslice" "$BENCH_DIR/bin/dropslice"
DS="$BENCH_DIR/bin/dropslice"
{
  echo "commit: $(git -C "$ROOT" describe --always --dirty 2>/dev/null || echo unknown)"
  echo "binary: $(sha256sum "$DS" | cut -c1-16)"
  echo "date: $(date -u +%FT%TZ)"
  echo "machine: $(nproc) cores, $(awk '/MemTotal/{printf "%.0f GiB", $2/1048576}' /proc/meminfo), $(lscpu | sed -n 's/^Model name: *//p' | head -1)"
} >"$BENCH_DIR/meta.txt"
log "$(tr '\n' ';' <"$BENCH_DIR/meta.txt")"

# ------------------------------------------------------------------ 2. peers
apt_install() {  # idempotent: only what is missing
  local missing=()
  for p in "$@"; do dpkg -s "$p" >/dev/null 2>&1 || missing+=("$p"); done
  [ ${#missing[@]} -eq 0 ] && return 0
  log "apt-get install ${missing[*]}"
  $SUDO apt-get update -qq >&2 && DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >&2
}
[ -x /usr/bin/time ] || apt_install time || { echo "need /usr/bin/time (package time)" >&2; exit 1; }

if [ "$PEERS" != 0 ]; then
  pkgs=()
  case " $TOOLS " in *" cura "*) pkgs+=(cura-engine) ;; esac
  case " $TOOLS " in *" prusa "*) pkgs+=(prusa-slicer) ;; esac
  apt_install "${pkgs[@]}" || { echo "peer install failed (BENCH_PEERS=0 to skip peers)" >&2; exit 1; }
  [ -f "$PEERS_SH" ] || { echo "missing $PEERS_SH" >&2; exit 1; }
  # the exact peer command lines: function definitions read from peers.sh
  eval "$(sed -n -e '/^run_prusa() {/,/^}/p' -e '/^run_cura() {/,/^}/p' -e '/^layers_of() {/,/^}/p' "$PEERS_SH")"
  for f in run_prusa run_cura layers_of; do
    declare -F "$f" >/dev/null || { echo "could not read $f from $PEERS_SH" >&2; exit 1; }
  done
  # CuraEngine needs fdmprinter.def.json from the `cura` package (data only, as peers.sh does)
  if [ -z "${CURA_DEFS:-}" ]; then
    if [ -f /usr/share/cura/resources/definitions/fdmprinter.def.json ]; then
      CURA_DEFS=/usr/share/cura/resources/definitions
    else
      CURA_DEFS="$BENCH_DIR/cura-deb/usr/share/cura/resources/definitions"
      if [ ! -f "$CURA_DEFS/fdmprinter.def.json" ]; then
        log "unpacking Cura's machine definitions (apt-get download cura)"
        (cd "$BENCH_DIR" && rm -f cura_*.deb && apt-get download cura >&2 && dpkg-deb -x cura_*.deb "$BENCH_DIR/cura-deb") ||
          { echo "could not unpack the cura package for fdmprinter.def.json" >&2; exit 1; }
      fi
    fi
  fi
  OUT="$BENCH_DIR/peers"  # run_prusa keeps its --datadir under $OUT
  mkdir -p "$OUT"
  export CURA_DEFS OUT
fi

# ------------------------------------------------------------------ 3. models
gen_torus() {  # $1 = facets, $2 = "z4" to stretch 4x in z
  local n="$1" f="$BENCH_DIR/models/torus_$1.stl"
  if [ ! -s "$f" ]; then
    log "gen_mesh.py -n $n"
    python3 "$SHARED/tools/gen_mesh.py" -n "$n" -o "$f.tmp" >&2 && mv "$f.tmp" "$f" || return 1
  fi
  if [ "${2:-}" = z4 ]; then
    local g="$BENCH_DIR/models/torus_$1_z4.stl"
    if [ ! -s "$g" ]; then
      log "stretching torus_$n 4x in z"
      python3 - "$f" "$g.tmp" <<'EOF' >&2 && mv "$g.tmp" "$g" || return 1
import sys, numpy as np
src, dst = sys.argv[1], sys.argv[2]
raw = open(src, "rb").read()
n = int(np.frombuffer(raw[80:84], "<u4")[0])
rec = np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")])
t = np.frombuffer(raw[84:84 + 50 * n], rec).copy()
t["v"][:, :, 2] *= 4.0
nz = t["n"].astype(np.float64); nz[:, 2] /= 4.0
nz /= np.maximum(np.linalg.norm(nz, axis=1, keepdims=True), 1e-30)
t["n"] = nz.astype(np.float32)
with open(dst, "wb") as o:
    o.write(b"torus stretched 4x in z (dropslice bench)".ljust(80, b" "))
    o.write(np.uint32(n).tobytes()); o.write(t.tobytes())
print(f"wrote {dst}: {n} triangles, z x4", file=sys.stderr)
EOF
    fi
    echo "$g"
  else
    echo "$f"
  fi
}

resolve_model() {  # name or path -> path
  local m="$1"
  if [ -f "$m" ]; then echo "$m"; return; fi
  if [ -f "$SHARED/models/$m.stl" ]; then echo "$SHARED/models/$m.stl"; return; fi
  if [[ "$m" =~ ^torus_([0-9]+)_z4$ ]]; then gen_torus "${BASH_REMATCH[1]}" z4; return; fi
  if [[ "$m" =~ ^torus_([0-9]+)$ ]]; then gen_torus "${BASH_REMATCH[1]}"; return; fi
  echo "unknown model $m" >&2; return 1
}

if [ -n "${BENCH_MODELS:-}" ]; then
  read -r -a names <<<"$BENCH_MODELS"
else
  names=()
  for f in "$SHARED"/models/*.stl; do names+=("$(basename "$f" .stl)"); done
  names+=(torus_100000 torus_1000000 torus_4000000 torus_1000000_z4)
fi
MODELS=()
for m in "${names[@]}"; do p="$(resolve_model "$m")" && MODELS+=("$p") || exit 1; done

facets_of() {  # binary by the size rule, else count ASCII facets
  python3 -c "import struct,sys,os;b=open(sys.argv[1],'rb').read(84);n=struct.unpack('<I',b[80:84])[0];print(n if 84+50*n==os.path.getsize(sys.argv[1]) else sum(1 for l in open(sys.argv[1],errors='replace') if l.lstrip().startswith('facet')))" "$1"
}

# ------------------------------------------------------------------ 4. runs
run_dropslice() {  # $1 = model, $2 = output
  # allow_off_plate: the bench times slicing; a model wider than the default plate (the
  # bunny) is sliced where it lies, as the peers slice it, instead of refused.
  # shellcheck disable=SC2086
  "$DS" "$1" -o "$2" -q --set allow_off_plate=true $DS_ARGS
}
layers_dropslice() { sed -n 's/^; layers = \([0-9]*\).*/\1/p' "$1" | head -1; }

one_run() {  # $1 tool, $2 model, $3 gcode, $4 time file, $5 log
  case "$1" in
    dropslice) /usr/bin/time -v -o "$4" timeout "$TIMEOUT" "$DS" "$2" -o "$3" -q $DS_ARGS >"$5" 2>&1 ;;
    *) /usr/bin/time -v -o "$4" timeout "$TIMEOUT" bash -c "$(declare -f "run_$1"); OUT='$OUT'; CURA_DEFS='$CURA_DEFS'; run_$1 '$2' '$3'" >"$5" 2>&1 ;;
  esac
}

RAW="$BENCH_DIR/raw.tsv"
printf 'model\tfacets\ttool\trun\trc\twall_s\tuser_s\tsys_s\tpeak_kb\tlayers\tgcode_bytes\tload1\n' >"$RAW"
log "models: ${names[*]}; tools: $TOOLS; $WARMUP warm-up + $RUNS timed runs each"
# Runs are interleaved (run 1 of every tool, then run 2, ...), so a burst of other work
# on the machine does not land on one tool's runs only.
for m in "${MODELS[@]}"; do
  name="$(basename "$m" .stl)"
  facets="$(facets_of "$m")"
  tools=()
  for tool in $TOOLS; do
    if [ "$tool" != dropslice ] && [[ " $PEER_SKIP " == *" $name "* ]]; then
      log "$name: $tool skipped (BENCH_PEER_SKIP)"; continue
    fi
    tools+=("$tool")
    for w in $(seq 1 "$WARMUP"); do
      one_run "$tool" "$m" "$BENCH_DIR/gcode/$name.$tool.gcode" /dev/null /dev/null
    done
  done
  for run in $(seq 1 "$RUNS"); do
    for tool in "${tools[@]}"; do
      g="$BENCH_DIR/gcode/$name.$tool.gcode"
      tf="$BENCH_DIR/logs/$name.$tool.$run.time"; lf="$BENCH_DIR/logs/$name.$tool.$run.log"
      rm -f "$g"
      load1=$(cut -d' ' -f1 /proc/loadavg)  # other work on the machine shows here
      one_run "$tool" "$m" "$g" "$tf" "$lf"; rc=$?
      wall=$(awk -F': ' '/Elapsed \(wall clock\)/{n=split($2,a,":"); s=0; for(i=1;i<=n;i++) s=s*60+a[i]; print s}' "$tf")
      user=$(awk -F': ' '/User time/{print $2}' "$tf"); sys=$(awk -F': ' '/System time/{print $2}' "$tf")
      peak=$(awk -F': ' '/Maximum resident set size/{print $2}' "$tf")
      if [ -s "$g" ]; then
        if [ "$tool" = dropslice ]; then lay=$(layers_dropslice "$g"); else lay=$(layers_of "$tool" "$g"); fi
        sz=$(stat -c %s "$g")
      else lay=0; sz=0; fi
      printf '%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\n' "$name" "$facets" "$tool" "$run" "$rc" "$wall" "$user" "$sys" "$peak" "${lay:-0}" "$sz" "$load1" >>"$RAW"
      log "$name $tool run $run: rc=$rc wall=${wall}s peak=$((peak / 1024))MB layers=$lay load=$load1"
    done
  done
  for tool in "${tools[@]}"; do rm -f "$BENCH_DIR/gcode/$name.$tool.gcode"; done  # big; keep only the numbers
done

# ------------------------------------------------------------------ 5. browser (optional)
BROWSER_TSV="$BENCH_DIR/browser.tsv"
rm -f "$BROWSER_TSV"
if [ "${BENCH_BROWSER:-0}" = 1 ]; then
  H="$ROOT/tests/e2e/helpers.mjs"
  todo=""
  if ! { [ -f "$H" ] && grep -q 'export async function start' "$H" && grep -q 'export async function waitSettled' "$H"; }; then
    todo="tests/e2e/helpers.mjs (start/openPage/waitSettled) is missing"
  elif [ ! -x /usr/bin/chromium ]; then
    todo="/usr/bin/chromium is missing (apt-get install chromium)"
  else
    log "building the page (scripts/build.sh) for the browser timing"
    bash scripts/build.sh >&2 || todo="the page build failed (scripts/build.sh; node_modules missing? npm run setup)"
  fi
  if [ -n "$todo" ]; then
    echo "TODO(browser): $todo; no browser timing was made" >&2
    printf 'TODO\t%s\n' "$todo" >"$BROWSER_TSV"
  else
    torus1m="$(resolve_model torus_1000000)"
    cat >"$BENCH_DIR/browser_bench.mjs" <<EOF
// generated by scripts/bench.sh: slice files in the page, warm-up + N timed runs each
import { start, timeVisits, waitSettled } from "$H";
const runs = Number(process.env.BENCH_RUNS ?? 3);
const files = process.argv.slice(2);
const env = await start();
try {
  for (const f of files) {
    await timeVisits(env, runs, async (page, i) => {
      // responsiveness: the longest gap between ticks of a 16 ms timer on the page's thread
      // while it slices (a long task there would freeze the page)
      await page.evaluate(() => {
        const g = (window.__gap = { max: 0, last: performance.now() });
        g.timer = setInterval(() => {
          const now = performance.now();
          g.max = Math.max(g.max, now - g.last);
          g.last = now;
        }, 16);
      });
      const t0 = Date.now();
      await page.setInputFiles("#file-input", f);
      await page.waitForFunction(() => document.body.dataset.state === "slicing", null, { timeout: 120_000 }).catch(() => {});
      const s = await waitSettled(page, 900_000);
      // the page's own clock (file chosen -> every layer's G-code ready); the outer one also
      // counts playwright handing the file over and polling the state
      const outer = (Date.now() - t0) / 1000;
      const gap = await page.evaluate(() => (clearInterval(window.__gap.timer), window.__gap.max));
      const dt = s.seconds ?? outer;
      if (s.state !== "done") throw new Error(\`\${f}: page state \${s.state}\`);
      console.error(\`[browser] \${f} run \${i}\${i ? "" : " (warm-up)"}: \${dt.toFixed(2)} s (outer \${outer.toFixed(2)} s), longest timer gap \${gap.toFixed(0)} ms, \${s.layers} layers, \${s.workers} worker(s)\`);
      if (i > 0) console.log([f.split("/").pop().replace(/\.stl$/, ""), i, dt, s.layers, s.workers, gap.toFixed(0)].join("\t"));
      return dt;
    });
  }
} finally {
  await env.close();
}
EOF
    node "$BENCH_DIR/browser_bench.mjs" "$SHARED/models/3DBenchy.stl" "$torus1m" >"$BROWSER_TSV" ||
      printf 'TODO\t%s\n' "the browser timing failed (see the messages above)" >"$BROWSER_TSV"
  fi
fi

# ------------------------------------------------------------------ 6. report
args=("$RAW")
[ -f "$BROWSER_TSV" ] && args+=(--browser "$BROWSER_TSV")
{ sed 's/^/    /' "$BENCH_DIR/meta.txt"; echo; python3 "$ROOT/scripts/bench_report.py" "${args[@]}"; } | tee "$BENCH_DIR/report.md"

#!/usr/bin/env bash
# Builds stepnc in Release, makes a large Part 21 file from a corpus file (if
# missing), runs the Part 21 reader benchmarks pinned to one core, measures the
# peak memory and end-to-end time of `stepnc check` and `stepnc convert`, and
# prints a summary. The figures in docs/performance.md come from this script.
#
#   bench/run-part21-bench.sh
#
# Environment (all optional):
#   BUILD_DIR   build folder                         (default: build)
#   JOBS        ninja jobs; the machine is shared     (default: 2)
#   SOURCE      corpus file to repeat                 (default: $STEPNC_CORPUS_DIR/unseenlaser__iso-14649-toolkit/ex1E.stp,
#               STEPNC_CORPUS_DIR defaulting to ../shared/corpus next to the repository)
#   SIZE_MB     size of the generated file, in 10^6 bytes     (default: 100)
#   BIG         the generated file               (default: bench/data/<source name>-<SIZE_MB>MB.stp)
#   CPU         core to pin to with taskset           (default: 0)
#   REPS        benchmark repetitions (median taken)  (default: 5)
#   RUNS        end-to-end runs of `stepnc check`     (default: 5)
#   OUT_DIR     where results go                      (default: bench/data/results)
#   SKIP_BUILD  1: use the binaries already in BUILD_DIR (e.g. while a
#               concurrent change elsewhere in the tree breaks the build)
set -euo pipefail

ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$ROOT"

BUILD_DIR=${BUILD_DIR:-build}
JOBS=${JOBS:-2}
CORPUS_DIR=${STEPNC_CORPUS_DIR:-$ROOT/../shared/corpus}
SOURCE=${SOURCE:-$CORPUS_DIR/unseenlaser__iso-14649-toolkit/ex1E.stp}
SIZE_MB=${SIZE_MB:-100}
BIG=${BIG:-bench/data/$(basename "${SOURCE%.*}")-${SIZE_MB}MB.stp}
CPU=${CPU:-0}
REPS=${REPS:-5}
RUNS=${RUNS:-5}
OUT_DIR=${OUT_DIR:-bench/data/results}
STEPNC=$BUILD_DIR/bin/stepnc
BENCH=$BUILD_DIR/bin/stepnc-bench

say() { printf '\n== %s\n' "$*" >&2; }

PIN=()
if command -v taskset >/dev/null 2>&1; then
  PIN=(taskset -c "$CPU")
else
  echo "run-part21-bench: taskset not found; benchmarks are not pinned" >&2
fi
TIME=/usr/bin/time
if [[ ! -x $TIME ]]; then
  echo "run-part21-bench: $TIME not found (apt-get install time); peak memory not measured" >&2
  TIME=
fi

if [[ ${SKIP_BUILD:-0} == 1 ]]; then
  say "build skipped (SKIP_BUILD=1): using $STEPNC and $BENCH as they are"
else
  say "build (Release) in $BUILD_DIR"
  cmake -S . -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
  ninja -C "$BUILD_DIR" -j"$JOBS" stepnc stepnc-bench
fi

mkdir -p "$(dirname "$BIG")" "$OUT_DIR"
if [[ ! -s $BIG ]]; then
  say "generate $BIG from $SOURCE"
  python3 bench/gen-large-p21.py "$SOURCE" "$BIG" --size-mb "$SIZE_MB"
fi
BYTES=$(stat -c %s "$BIG")

say "validate $BIG"
"$STEPNC" check "$BIG" | tee "$OUT_DIR/check.txt"
if ! grep -q '; 0 errors' "$OUT_DIR/check.txt"; then
  echo "run-part21-bench: $BIG has errors; fix the generator or the reader first" >&2
  exit 1
fi

# Warm the page cache (the targets are for a file already in the cache).
cat "$BIG" >/dev/null

say "machine"
{
  echo "date: $(date -u +%Y-%m-%dT%H:%M:%SZ)"
  echo "commit: $(git rev-parse --short HEAD 2>/dev/null || echo unknown)$(git diff --quiet HEAD -- frontend/part21 support 2>/dev/null || echo ' + uncommitted changes in frontend/part21 or support')"
  echo "cpu: $(lscpu | sed -n 's/^Model name: *//p' | head -1), $(nproc) cores"
  echo "compiler: $(c++ --version | head -1)"
  echo "kernel: $(uname -r)"
  echo "load average before: $(cut -d' ' -f1-3 /proc/loadavg)"
  echo "input: $BIG, $BYTES bytes"
} | tee "$OUT_DIR/machine.txt"

say "benchmarks (${PIN[*]:-unpinned}, $REPS repetitions)"
"${PIN[@]}" "$BENCH" --file="$BIG" \
  --benchmark_repetitions="$REPS" \
  --benchmark_out="$OUT_DIR/bench.json" --benchmark_out_format=json

# `stepnc check` checks against the built-in ISO 14649 schema by default;
# `--no-schema` is the Part 21 reader alone (read + decode + reference checks).
CHECKS=("check")
if "$STEPNC" check --help 2>/dev/null | grep -q -- '--no-schema'; then
  CHECKS=("check --no-schema" "check")
fi

if [[ -n $TIME ]]; then
  for c in "${CHECKS[@]}"; do
    tag=${c// /}
    say "peak memory: stepnc $c"
    # shellcheck disable=SC2086  # $c is a subcommand plus options
    "${PIN[@]}" "$TIME" -v "$STEPNC" $c "$BIG" 2>"$OUT_DIR/time-$tag.txt" >/dev/null
    grep -E 'Maximum resident|Elapsed' "$OUT_DIR/time-$tag.txt"
  done
  say "peak memory: stepnc convert"
  CONVERTED=$(mktemp /tmp/stepnc-bench-convert.XXXXXX.stp)
  "${PIN[@]}" "$TIME" -v "$STEPNC" convert "$BIG" -o "$CONVERTED" 2>"$OUT_DIR/time-convert.txt" >/dev/null
  grep -E 'Maximum resident|Elapsed' "$OUT_DIR/time-convert.txt"
  rm -f "$CONVERTED"
fi

for c in "${CHECKS[@]}"; do
  tag=${c// /}
  say "end to end: stepnc $c ($RUNS runs)"
  if command -v hyperfine >/dev/null 2>&1; then
    hyperfine --warmup 1 --runs "$RUNS" --export-json "$OUT_DIR/hyperfine-$tag.json" \
      "${PIN[*]} $STEPNC $c $BIG"
  elif [[ -n $TIME ]]; then
    : >"$OUT_DIR/loop-$tag.txt"
    for _ in $(seq "$RUNS"); do
      # shellcheck disable=SC2086
      "${PIN[@]}" "$TIME" -f '%e' "$STEPNC" $c "$BIG" 2>>"$OUT_DIR/loop-$tag.txt" >/dev/null
    done
    cat "$OUT_DIR/loop-$tag.txt"
  fi
done
echo "load average after: $(cut -d' ' -f1-3 /proc/loadavg)" | tee -a "$OUT_DIR/machine.txt"

say "summary"
python3 - "$OUT_DIR" "$BYTES" <<'EOF'
import json, os, re, statistics, sys

out_dir, size = sys.argv[1], int(sys.argv[2])
MB = 1e6
targets = {"BM_InstanceTable": 1000.0, "BM_DecodeAll": 300.0}

with open(os.path.join(out_dir, "bench.json")) as f:
    bench = json.load(f)
runs = {}
for b in bench["benchmarks"]:
    if b.get("run_type") != "iteration" or b.get("error_occurred"):
        continue
    name = b["run_name"]
    runs.setdefault(name, []).append(b)
scale = {"ns": 1e-9, "us": 1e-6, "ms": 1e-3, "s": 1.0}
print(f"input: {size / MB:.1f} MB")
print("MB/s = 10^6 bytes of input per second; median (and best) of the repetitions")
print(f"{'benchmark':<20}{'MB/s cpu':>10}{'(best)':>8}{'MB/s real':>11}{'ms/iter':>9}{'reps':>6}  target")
for name, rs in runs.items():
    cpus = [r["bytes_per_second"] / MB for r in rs]
    real = statistics.median(size / (r["real_time"] * scale[r["time_unit"]]) for r in rs) / MB
    ms = statistics.median(r["cpu_time"] * scale[r["time_unit"]] for r in rs) * 1e3
    cpu = statistics.median(cpus)
    t = targets.get(name)
    verdict = "" if t is None else f">= {t:.0f} MB/s: {'met' if cpu >= t else 'MISSED'}"
    print(f"{name:<20}{cpu:>10.0f}{max(cpus):>8.0f}{real:>11.0f}{ms:>9.1f}{len(rs):>6}  {verdict}")

def rss(path):
    try:
        text = open(path).read()
    except OSError:
        return None
    m = re.search(r"Maximum resident set size \(kbytes\): (\d+)", text)
    return int(m.group(1)) * 1024 if m else None

commands = [("check--no-schema", "check --no-schema"), ("check", "check"), ("convert", "convert")]
for tag, what in commands:
    r = rss(os.path.join(out_dir, f"time-{tag}.txt"))
    if r:
        ratio = r / size
        print(f"peak RSS stepnc {what:<17}: {r / MB:6.1f} MB = {ratio:.2f} x file size"
              f"  (target <= 1.5 x: {'met' if ratio <= 1.5 else 'MISSED'})")

for tag, what in commands:
    times = None
    hf = os.path.join(out_dir, f"hyperfine-{tag}.json")
    loop = os.path.join(out_dir, f"loop-{tag}.txt")
    if os.path.exists(hf):
        times = json.load(open(hf))["results"][0]["times"]
    elif os.path.exists(loop):
        times = [float(x) for x in open(loop).read().split()]
    if times:
        med = statistics.median(times)
        print(f"stepnc {what:<17} end to end: median {med:.3f} s of {len(times)} runs"
              f" ({size / MB / med:.0f} MB/s), min {min(times):.3f} s, max {max(times):.3f} s")
EOF

#!/usr/bin/env bash
# Strategy expansion figures for docs/performance.md: the expansion benchmarks
# (contour-parallel pockets of 100 to 10,000 outline vertices, the offset, and
# expansion with verification) pinned to one core, then the corpus end to end:
# every corpus file that expands, and the bundled example, compiled to the
# verified toolpath IR, and expanded without verification.
#
#   bench/run-expand-bench.sh
#
# Environment (all optional):
#   BUILD_DIR   build folder                     (default: build)
#   CPU         core to pin to with taskset      (default: 1)
#   STEPNC_CORPUS_DIR  the sample corpus         (default: ../shared/corpus beside the repository)
set -euo pipefail

ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$ROOT"
BUILD_DIR=${BUILD_DIR:-build}
CPU=${CPU:-1}
CORPUS_DIR=${STEPNC_CORPUS_DIR:-$ROOT/../shared/corpus}

ninja -C "$BUILD_DIR" stepnc stepnc-expand-bench >/dev/null
taskset -c "$CPU" "$BUILD_DIR/bin/stepnc-expand-bench" --benchmark_min_time=0.2

FILES=(
  "$CORPUS_DIR/jucsr__sanssouci/OnePocket"
  "$CORPUS_DIR/jucsr__sanssouci/RanhuraPerfilRoundedU.p21"
  "$CORPUS_DIR/jucsr__sanssouci/RanhuraPerfilUQuadrado.p21"
  "$CORPUS_DIR/jucsr__sanssouci/STEP-NC_Slot1 File.p21"
  "$CORPUS_DIR/jucsr__sanssouci/oneHoleOneSlotOneStepOnePoket.p21"
  "$CORPUS_DIR/unseenlaser__iso-14649-toolkit/ex1.stp"
  "$CORPUS_DIR/unseenlaser__iso-14649-toolkit/ex1E.stp"
  "$ROOT/examples/example1.stp"
)
for f in "${FILES[@]}"; do
  [ -e "$f" ] || { echo "missing $f (set STEPNC_CORPUS_DIR)" >&2; exit 1; }
done

moves=0
for f in "${FILES[@]}"; do
  n=$("$BUILD_DIR/bin/stepnc" compile "$f" --emit=toolpath-ir --stats -o /dev/null 2>&1 |
      sed -n 's/^stats: expand-strategies: \([0-9]*\) moves$/\1/p')
  moves=$((moves + ${n:-0}))
done
echo "corpus: ${#FILES[@]} files, $moves moves"
echo "compile --emit=toolpath-ir (expand and verify):"
time (for f in "${FILES[@]}"; do taskset -c "$CPU" "$BUILD_DIR/bin/stepnc" compile "$f" --emit=toolpath-ir -o /dev/null 2>/dev/null; done)
echo "opt --passes=resolve-feeds,expand-strategies (expand only):"
time (for f in "${FILES[@]}"; do taskset -c "$CPU" "$BUILD_DIR/bin/stepnc" opt "$f" --passes=resolve-feeds,expand-strategies -o /dev/null 2>/dev/null; done)

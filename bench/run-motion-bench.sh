#!/usr/bin/env bash
# Motion planning and playback figures for docs/performance.md: planning
# throughput on a 100,000-move path and the time to simulate about an hour of
# motion at 1 kHz (bench/MotionBench.cpp), pinned to one core; then every
# corpus file that expands, planned and played end to end with `stepnc sim`.
#
#   bench/run-motion-bench.sh
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

ninja -C "$BUILD_DIR" stepnc stepnc-motion-bench >/dev/null
taskset -c "$CPU" "$BUILD_DIR/bin/stepnc-motion-bench" --benchmark_repetitions=3 --benchmark_report_aggregates_only=true

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
if [ -d "$CORPUS_DIR" ]; then
  echo "compile, plan and play every file (stepnc sim, hsc-3axis):"
  start=$(date +%s.%N)
  for f in "${FILES[@]}"; do
    taskset -c "$CPU" "$BUILD_DIR/bin/stepnc" sim "$f" --machine=hsc-3axis 2>/dev/null |
      sed -n "s|^cycle time: \([0-9.]*\) s.*|  $(basename "$f"): \1 s of motion|p"
  done
  end=$(date +%s.%N)
  echo "  total wall time: $(python3 -c "print(round($end - $start, 2))") s"
else
  echo "corpus not found at $CORPUS_DIR: end-to-end timing skipped"
fi

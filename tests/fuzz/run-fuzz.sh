#!/usr/bin/env bash
# Builds (if needed) and runs the Part 21 libFuzzer target with one worker.
#
#   tests/fuzz/run-fuzz.sh [SECONDS] [extra libFuzzer flags...]
#
# SECONDS defaults to 600. Environment:
#   STEPNC_FUZZ_BUILD   build directory (default: <repo>/build-fuzz); it is
#                       configured with clang and -DSTEPNC_BUILD_FUZZ=ON if new
#   STEPNC_CORPUS_DIR   the read-only sample corpus (default: <repo>/../shared/corpus)
#   KEEP_GOING=1        run in -fork=1 mode and carry on past crashes, timeouts
#                       and OOMs (each one is still saved under fuzz-artifacts/)
#
# The seeds (corpus Part 21 files, tests/fuzz/seeds, tests/fuzz/regressions)
# are copied into <build>/fuzz-seeds; inputs the fuzzer finds go to
# <build>/fuzz-corpus and crashes to <build>/fuzz-artifacts. Nothing is written
# into the source tree.
set -euo pipefail

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
root=$(cd "$here/../.." && pwd)
build=${STEPNC_FUZZ_BUILD:-$root/build-fuzz}
corpus_src=${STEPNC_CORPUS_DIR:-$root/../shared/corpus}
seconds=${1:-600}
[[ $# -gt 0 ]] && shift

# --- build -------------------------------------------------------------------
if [[ ! -f $build/build.ninja ]]; then
  CC=${CC:-clang} CXX=${CXX:-clang++} cmake -S "$root" -B "$build" -G Ninja \
    -DSTEPNC_BUILD_FUZZ=ON -DSTEPNC_BUILD_TESTS=OFF -DSTEPNC_BUILD_BENCH=OFF \
    -DCMAKE_BUILD_TYPE=RelWithDebInfo
fi
cmake --build "$build" --target part21-fuzzer -j1
fuzzer=$build/bin/part21-fuzzer

# --- seeds -------------------------------------------------------------------
seeds=$build/fuzz-seeds
work=$build/fuzz-corpus
artifacts=$build/fuzz-artifacts
mkdir -p "$seeds" "$work" "$artifacts"
copy_seed() {  # copy_seed FILE PREFIX: flat, space-free names
  local name
  name=$(basename "$1")
  cp -f -- "$1" "$seeds/${2}__${name// /_}"
}
if [[ -d $corpus_src ]]; then
  while IFS= read -r -d '' f; do
    copy_seed "$f" "$(basename "$(dirname "$f")")"
  done < <(find "$corpus_src" -type f \( -name '*.stp' -o -name '*.p21' -o -name '*.stpnc' \) -print0)
  if [[ -d $corpus_src/jucsr__sanssouci ]]; then
    while IFS= read -r -d '' f; do
      copy_seed "$f" jucsr__sanssouci
    done < <(find "$corpus_src/jucsr__sanssouci" -maxdepth 1 -type f ! -name '*.*' -print0)
  fi
else
  echo "run-fuzz.sh: no sample corpus at $corpus_src; using the hand-made seeds only" >&2
fi
# The project's own Part 21 files: hand-made seeds, regressions, the error
# tests (with --verify-diagnostics annotations), test inputs and the example.
for f in "$here"/seeds/* "$here"/regressions/*.p21 "$root"/tests/frontend/part21/errors/*.p21 \
         "$root"/tests/Inputs/*.stp "$root"/examples/*.stp; do
  [[ -f $f ]] && copy_seed "$f" "$(basename "$(dirname "$f")")"
done
echo "run-fuzz.sh: $(ls "$seeds" | wc -l) seed files in $seeds" >&2

# --- run ---------------------------------------------------------------------
flags=(
  -max_total_time="$seconds"
  -max_len=65536
  -timeout=5
  -rss_limit_mb=2048
  -dict="$here/part21.dict"
  -artifact_prefix="$artifacts/"
  -print_final_stats=1
)
if [[ ${KEEP_GOING:-0} == 1 ]]; then
  flags+=(-fork=1 -ignore_crashes=1 -ignore_timeouts=1 -ignore_ooms=1)
fi
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
exec "$fuzzer" "${flags[@]}" "$@" "$work" "$seeds"

#!/usr/bin/env bash
# Builds (if needed) and runs one of stepnc's libFuzzer targets with one worker.
#
#   tests/fuzz/run-fuzz.sh [TARGET] [SECONDS] [extra libFuzzer flags...]
#
# TARGET is part21 (the default), part28, ir, native or toml; SECONDS
# defaults to 600. Environment:
#   STEPNC_FUZZ_BUILD   build directory (default: <repo>/build-fuzz); it is
#                       configured with clang (CC/CXX, default clang-16) and
#                       -DSTEPNC_BUILD_FUZZ=ON if new
#   STEPNC_CORPUS_DIR   the read-only sample corpus (default: <repo>/../shared/corpus)
#   STEPNC              a stepnc binary that makes more seeds from the examples
#                       (Part 28, IR text, native motion); default
#                       <repo>/build/bin/stepnc when it exists
#   KEEP_GOING=1        run in -fork=1 mode and carry on past crashes, timeouts
#                       and OOMs (each one is still saved under fuzz-artifacts/)
#
# The seeds are copied into <build>/fuzz-seeds-TARGET; inputs the fuzzer
# finds go to <build>/fuzz-corpus-TARGET and crashes to
# <build>/fuzz-artifacts-TARGET. Nothing is written into the source tree.
set -euo pipefail

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
root=$(cd "$here/../.." && pwd)
build=${STEPNC_FUZZ_BUILD:-$root/build-fuzz}
corpus_src=${STEPNC_CORPUS_DIR:-$root/../shared/corpus}
target=part21
if [[ $# -gt 0 && ! $1 =~ ^[0-9]+$ && ! $1 =~ ^- ]]; then
  target=$1
  shift
fi
case $target in
  part21 | part28 | ir | native | toml) ;;
  *) echo "run-fuzz.sh: unknown target '$target' (part21, part28, ir, native, toml)" >&2; exit 2 ;;
esac
seconds=${1:-600}
[[ $# -gt 0 ]] && shift
stepnc=${STEPNC:-$root/build/bin/stepnc}

# --- build -------------------------------------------------------------------
if [[ ! -f $build/build.ninja ]]; then
  "$root/scripts/install-deps.sh" --fuzz
  CC=${CC:-clang-16} CXX=${CXX:-clang++-16} cmake -S "$root" -B "$build" -G Ninja \
    -DSTEPNC_BUILD_FUZZ=ON -DSTEPNC_BUILD_TESTS=OFF -DSTEPNC_BUILD_BENCH=OFF \
    -DCMAKE_BUILD_TYPE=RelWithDebInfo
fi
cmake --build "$build" --target "$target-fuzzer" -j1
fuzzer=$build/bin/$target-fuzzer

# --- seeds -------------------------------------------------------------------
seeds=$build/fuzz-seeds-$target
work=$build/fuzz-corpus-$target
artifacts=$build/fuzz-artifacts-$target
mkdir -p "$seeds" "$work" "$artifacts"
copy_seed() {  # copy_seed FILE PREFIX: flat, space-free names
  local name
  name=$(basename "$1")
  cp -f -- "$1" "$seeds/${2}__${name// /_}"
}
copy_all() {  # copy_all FILE...: each under its folder's name
  local f
  for f in "$@"; do
    [[ -f $f ]] && copy_seed "$f" "$(basename "$(dirname "$f")")"
  done
  return 0
}
corpus_part21() {  # the sample corpus's Part 21 files, NUL-separated
  [[ -d $corpus_src ]] || return 0
  find "$corpus_src" -type f \( -name '*.stp' -o -name '*.p21' -o -name '*.stpnc' \) -print0
  if [[ -d $corpus_src/jucsr__sanssouci ]]; then
    find "$corpus_src/jucsr__sanssouci" -maxdepth 1 -type f ! -name '*.*' -print0
  fi
}
# make_seeds KIND EXT ARGS...: what `stepnc compile` (or convert, for xml)
# writes for the examples and the sample corpus, when a stepnc is at hand.
make_seeds() {
  local kind=$1 ext=$2 f out
  shift 2
  if [[ ! -x $stepnc ]]; then
    echo "run-fuzz.sh: no stepnc at $stepnc: no $kind seeds made from the examples" >&2
    return 0
  fi
  while IFS= read -r -d '' f; do
    out="$seeds/made__$(basename "$(dirname "$f")")__$(basename "$f").$ext"
    out=${out// /_}
    if [[ $kind == xml ]]; then
      timeout 60 "$stepnc" convert "$f" -o "$out" >/dev/null 2>&1 || rm -f "$out"
    else
      timeout 60 "$stepnc" compile "$f" "$@" -o "$out" >/dev/null 2>&1 || rm -f "$out"
    fi
    # Seeds beyond libFuzzer's -max_len would only be cut.
    if [[ -f $out && $(stat -c %s "$out") -gt 65536 ]]; then rm -f "$out"; fi
  done < <(
    find "$root/examples" "$root/tests/Inputs" -maxdepth 2 -name '*.stp' -print0
    corpus_part21
  )
}

case $target in
  part21)
    if [[ -d $corpus_src ]]; then
      while IFS= read -r -d '' f; do copy_seed "$f" "$(basename "$(dirname "$f")")"; done < <(corpus_part21)
    else
      echo "run-fuzz.sh: no sample corpus at $corpus_src; using the project's seeds only" >&2
    fi
    # The project's own Part 21 files: hand-made seeds, regressions, the error
    # tests (with --verify-diagnostics annotations), test inputs and the example.
    copy_all "$here"/seeds/* "$here"/regressions/*.p21 "$root"/tests/frontend/part21/errors/*.p21 \
             "$root"/tests/Inputs/*.stp "$root"/examples/*.stp
    dict=(-dict="$here/part21.dict")
    ;;
  part28)
    copy_all "$root"/tests/Inputs/part28/*.stpx "$root"/tests/Inputs/part28-bad/*.stpx "$here"/regressions-part28/*
    make_seeds xml stpx
    dict=()
    ;;
  ir)
    copy_all "$root"/tests/ir/*.ir "$root"/tests/ir/process/*.ir "$root"/tests/Inputs/*.ir \
             "$root"/tests/runtime/Inputs/*.ir "$here"/regressions-ir/*
    make_seeds ir feature.ir --emit=feature-ir
    make_seeds ir toolpath.ir --emit=toolpath-ir --machine=hsc-3axis
    dict=()
    ;;
  native)
    copy_all "$here"/seeds-native/* "$here"/regressions-native/*
    make_seeds native motion --target=native --machine=hsc-3axis
    dict=()
    ;;
  toml)
    copy_all "$root"/machines/*.toml "$root"/tests/Inputs/machines/*.toml "$root"/cutting/materials.toml \
             "$here"/regressions-toml/*
    dict=()
    ;;
esac
echo "run-fuzz.sh: $(find "$seeds" -type f | wc -l) seed files in $seeds" >&2

# --- run ---------------------------------------------------------------------
flags=(
  -max_total_time="$seconds"
  -max_len=65536
  -timeout=5
  -rss_limit_mb=2048
  "${dict[@]}"
  -artifact_prefix="$artifacts/"
  -print_final_stats=1
)
if [[ ${KEEP_GOING:-0} == 1 ]]; then
  flags+=(-fork=1 -ignore_crashes=1 -ignore_timeouts=1 -ignore_ooms=1)
fi
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
exec "$fuzzer" "${flags[@]}" "$@" "$work" "$seeds"

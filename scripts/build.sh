#!/usr/bin/env bash
# Installs the dependencies (scripts/install-deps.sh) and builds stepnc.
#   scripts/build.sh              Release build in build/  -> build/bin/stepnc
#   scripts/build.sh --sanitize   ASan+UBSan build in build-asan/
# Extra arguments after -- go to CMake's configure step.
set -euo pipefail
cd "$(dirname "$0")/.."

dir=build
cmake_args=(-DCMAKE_BUILD_TYPE=Release)
while [ $# -gt 0 ]; do
  case "$1" in
    # -O1 -g1: half the compile time of -O2 -g (the sanitizer build is built
    # from scratch in every CI run), with the line tables the sanitizers'
    # reports need; the benchmarks are built and timed in the Release build.
    --sanitize) dir=build-asan
                cmake_args=(-DCMAKE_BUILD_TYPE=RelWithDebInfo "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g1 -DNDEBUG"
                            -DSTEPNC_SANITIZE=ON -DSTEPNC_BUILD_BENCH=OFF) ;;
    --) shift; cmake_args+=("$@"); break ;;
    *) echo "usage: $0 [--sanitize] [-- cmake-args...]" >&2; exit 2 ;;
  esac
  shift
done

scripts/install-deps.sh
cmake -S . -B "$dir" -G Ninja "${cmake_args[@]}" > "$dir.configure.log" 2>&1 || { cat "$dir.configure.log"; exit 1; }
cmake --build "$dir"

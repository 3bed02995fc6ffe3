#!/usr/bin/env bash
# Installs every Debian package stepnc needs to build, test and benchmark.
#   scripts/install-deps.sh          build, test, benchmark
#   scripts/install-deps.sh --fuzz   and clang 16 for the libFuzzer build (tests/fuzz)
# Idempotent and non-interactive: packages already present are left alone, and
# apt-get is only called when something is missing. Run as root (or with sudo).
# docs/dependencies.md says why each package is here.
set -euo pipefail

fuzz=0
case "${1:-}" in
  --fuzz) fuzz=1 ;;
  "") ;;
  *) echo "usage: $0 [--fuzz]" >&2; exit 2 ;;
esac

packages=(
  # toolchain
  build-essential cmake ninja-build python3 pkg-config
  # EXPRESS frontend: ANTLR 4.7.2 tool + 4.9 C++ runtime
  antlr4 libantlr4-runtime-dev
  # geometry
  libeigen3-dev libcgal-dev
  # command line, machine files, XML
  libcli11-dev libtomlplusplus-dev libxml2-dev libxml2-utils
  # tests: Catch2 unit tests, lit + FileCheck golden tests, LinuxCNC's rs274 interpreter
  catch2 llvm-14-tools linuxcnc-uspace
  # tests: Open CASCADE's STEP reader reads the STEP-NC stepnc writes back
  libocct-data-exchange-dev
  # benchmarks
  libbenchmark-dev
)
# fuzzing (libFuzzer ships with clang's runtime; 16, not 14, builds the ANTLR
# lexer): only the fuzz build needs it, not the tests CI runs.
if [ "$fuzz" = 1 ]; then
  packages+=(clang-16 libclang-rt-16-dev)
fi

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed'; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
echo "install-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"

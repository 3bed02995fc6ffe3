#!/usr/bin/env bash
# Installs the dependencies, builds and runs every test under ctest: first the
# Release build (build/), then the ASan+UBSan build (build-asan/).
#   scripts/test.sh           both configurations
#   scripts/test.sh --fast    Release only
# The sample corpus is looked up at $STEPNC_CORPUS, else ../shared/corpus; the
# tests that need it are reported as skipped when it is absent.
set -euo pipefail
cd "$(dirname "$0")/.."

sanitize=1
case "${1:-}" in
  --fast) sanitize=0 ;;
  "") ;;
  *) echo "usage: $0 [--fast]" >&2; exit 2 ;;
esac

jobs=$(nproc)
scripts/build.sh
(cd build && ctest --output-on-failure -j "$jobs")

if [ "$sanitize" = 1 ]; then
  scripts/build.sh --sanitize
  # Distinct exit codes so a sanitizer report is never mistaken for the
  # tool's own "input has errors" status (1).
  export ASAN_OPTIONS="detect_leaks=1:exitcode=86:strict_string_checks=1"
  export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1:exitcode=87"
  (cd build-asan && ctest --output-on-failure -j "$jobs")
fi

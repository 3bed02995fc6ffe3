#!/usr/bin/env bash
# The cycle-time comparison of docs/pattern-strategies.md: the same pocket
# (examples/patterns/*-pocket.stp, 60 x 40 x 20 mm, corner radius 10, D10 end
# mill) roughed by trochoidal loops, by plunges and by ordinary
# contour-parallel rings, each planned and played on every shipped machine
# with `stepnc sim`: first with the feeds as programmed (no feed
# adaptation), then with each strategy's feeds adapted to the cut on that
# machine, raised where the chip allows (--allow-feed-increase), which is
# where thin-chip strategies gain.
#
#   bench/run-pattern-comparison.sh
#
# Environment (optional): BUILD_DIR, the build folder (default: build).
set -euo pipefail

ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$ROOT"
BUILD_DIR=${BUILD_DIR:-build}
ninja -C "$BUILD_DIR" stepnc >/dev/null
STEPNC="$BUILD_DIR/bin/stepnc"
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT

MACHINES=(hsc-3axis conventional-3axis)
table() {
  local title=$1
  shift
  printf '\n%s\n\n| strategy | path (mm) |' "$title"
  for m in "${MACHINES[@]}"; do printf ' %s cycle time (s) |' "$m"; done
  printf '\n|---|---:|'
  for m in "${MACHINES[@]}"; do printf -- '---:|'; done
  printf '\n'
  for s in trochoidal plunge contour; do
    local path=""
    local row=""
    for m in "${MACHINES[@]}"; do
      local ir="$TMP/$s-$m.ir"
      "$STEPNC" compile "examples/patterns/$s-pocket.stp" --emit=toolpath-ir "$@" --machine "$m" -o "$ir" 2>/dev/null
      path=$(grep -o 'path [0-9.]* mm' "$ir" | head -1 | cut -d' ' -f2)
      row+=" $("$STEPNC" sim "$ir" --machine "$m" | sed -n 's/^cycle time: \([0-9.]*\) s.*/\1/p') |"
    done
    printf '| %s | %s |%s\n' "$s" "$path" "$row"
  done
}
table "Feeds as programmed" --no-adapt-feed
table "Feeds adapted to the cut on each machine, raised where the chip allows" --allow-feed-increase

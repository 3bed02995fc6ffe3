#!/usr/bin/env bash
# Deposition figures for docs/additive.md and docs/performance.md: slicing
# and bead paths (expand-strategies alone) of the die's truncated pyramid
# (tests/passes/additive/Inputs/pyramid.stp: 40 x 40 mm base, 20 mm high)
# at layers of 0.5, 0.25, 0.125 and 0.0625 mm (the bead height and the
# layer thickness set together), then the same with the independent check
# (verify-toolpaths), pinned to one core: the median wall time of REPEATS
# runs (default 5) and the peak memory, per layer count. Time per layer
# should stay flat (linear in layers).
#   bench/run-deposition-bench.sh [STEPNC] [REPEATS]
set -euo pipefail
cd "$(dirname "$0")/.."
stepnc=$(realpath "${1:-build/bin/stepnc}")
repeats=${2:-5}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
base=tests/passes/additive/Inputs/pyramid.stp

# median wall time (s) and peak memory (MiB) of `stepnc opt FILE -passes=P`
measure() {
  local file=$1 passes=$2 times=() mem=0
  for _ in $(seq "$repeats"); do
    /usr/bin/time -f '%e %M' -o "$work/t" taskset -c 0 "$stepnc" opt "$file" -passes="$passes" \
      -o /dev/null 2>/dev/null
    read -r t m < "$work/t"
    times+=("$t")
    (( m > mem )) && mem=$m
  done
  printf '%s %s\n' "$(printf '%s\n' "${times[@]}" | sort -n | sed -n "$(( (repeats + 1) / 2 ))p")" \
    "$(( mem / 1024 ))"
}

printf '%-8s %-7s %-22s %-22s\n' layer layers "expand: s, MiB" "expand+verify: s, MiB"
for h in 0.5 0.25 0.125 0.0625; do
  f=$work/pyramid-$h.stp
  sed -e "s/^#40=DEPOSITION_OPERATION(\$,\$,'deposit pyramid',#41,0.5,/#40=DEPOSITION_OPERATION(\$,\$,'deposit pyramid',#41,$h,/" \
      -e "s/^#43=DEPOSITION_TECHNOLOGY(0.01,.TCP.,900.,#44,2.,0.5,/#43=DEPOSITION_TECHNOLOGY(0.01,.TCP.,900.,#44,2.,$h,/" \
      "$base" > "$f"
  layers=$(awk -v h="$h" 'BEGIN { printf "%d", 20 / h + 0.5 }')
  printf '%-8s %-7s %-22s %-22s\n' "$h" "$layers" "$(measure "$f" expand-strategies)" \
    "$(measure "$f" expand-strategies,verify-toolpaths)"
done

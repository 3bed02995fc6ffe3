#!/usr/bin/env bash
# Times two stepnc builds compiling the same files, in turns, and prints the
# median wall time and peak memory of each per file: the check that a change
# left compile time and memory where they were.
#   bench/compare-compile.sh OLD_STEPNC NEW_STEPNC [REPEATS] [COMPILE ARGS...]
# Files: the bundled examples and every corpus file the new build compiles
# (at $STEPNC_CORPUS, else ../shared/corpus). Default arguments:
# --target=rs274. Runs alternate old, new, old, new so that a change in the
# machine's speed falls on both.
set -uo pipefail
cd "$(dirname "$0")/.."

if [ $# -lt 2 ]; then
  echo "usage: $0 OLD_STEPNC NEW_STEPNC [REPEATS] [COMPILE ARGS...]" >&2
  exit 2
fi
old=$(realpath "$1")
new=$(realpath "$2")
repeats=${3:-5}
shift $(( $# < 3 ? $# : 3 ))
args=("$@")
[ ${#args[@]} -eq 0 ] && args=(--target=rs274)
corpus=${STEPNC_CORPUS:-../shared/corpus}

files=()
while IFS= read -r -d '' f; do
  "$new" compile "$f" "${args[@]}" -o /dev/null 2>/dev/null && files+=("$f")
done < <({ find examples -name '*.stp' -print0; [ -d "$corpus" ] && find "$corpus" -type f \
  \( -name '*.stp' -o -name '*.p21' -o -name '*.stpnc' \) -print0; } | sort -z)

median() { sort -g | awk '{a[NR]=$1} END {print (NR % 2) ? a[(NR+1)/2] : (a[NR/2] + a[NR/2+1]) / 2}'; }

printf '%-60s %10s %10s %10s %10s\n' file old_ms new_ms old_MB new_MB
sum_old=0 sum_new=0
for f in "${files[@]}"; do
  : >/tmp/cc.old.t; : >/tmp/cc.new.t; : >/tmp/cc.old.m; : >/tmp/cc.new.m
  for _ in $(seq "$repeats"); do
    for side in old new; do
      bin=${!side}
      /usr/bin/time -f '%e %M' -o /tmp/cc.time "$bin" compile "$f" "${args[@]}" -o /dev/null 2>/dev/null
      read -r s kb </tmp/cc.time
      echo "$s" | awk '{print $1 * 1000}' >>"/tmp/cc.$side.t"
      echo "$kb" | awk '{print $1 / 1024}' >>"/tmp/cc.$side.m"
    done
  done
  to=$(median </tmp/cc.old.t) tn=$(median </tmp/cc.new.t)
  mo=$(median </tmp/cc.old.m) mn=$(median </tmp/cc.new.m)
  sum_old=$(echo "$sum_old $to" | awk '{print $1 + $2}')
  sum_new=$(echo "$sum_new $tn" | awk '{print $1 + $2}')
  printf '%-60s %10.0f %10.0f %10.1f %10.1f\n' "$(basename "$f" | cut -c1-60)" "$to" "$tn" "$mo" "$mn"
done
printf '%-60s %10.0f %10.0f\n' "total (sum of medians)" "$sum_old" "$sum_new"

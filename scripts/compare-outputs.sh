#!/usr/bin/env bash
# Runs two stepnc builds over the bundled examples, the test inputs and the
# sample corpus, on every emission and target, and reports every output that
# differs (program, IR, messages, exit status). A refactor that must change no
# output shows it here: "0 differ".
#   scripts/compare-outputs.sh OLD_STEPNC NEW_STEPNC [WORKDIR]
# The corpus is looked up at $STEPNC_CORPUS, else ../shared/corpus.
set -uo pipefail
cd "$(dirname "$0")/.."

if [ $# -lt 2 ]; then
  echo "usage: $0 OLD_STEPNC NEW_STEPNC [WORKDIR]" >&2
  exit 2
fi
old=$(realpath "$1")
new=$(realpath "$2")
work=${3:-$(mktemp -d)}
corpus=${STEPNC_CORPUS:-../shared/corpus}

inputs=()
while IFS= read -r -d '' f; do inputs+=("$f"); done < <(
  { find examples tests/Inputs -type f \( -name '*.stp' -o -name '*.p21' -o -name '*.stpx' \) -print0
    [ -d "$corpus" ] && find "$corpus" -type f \( -name '*.stp' -o -name '*.p21' -o -name '*.stpnc' -o -name '*.stpx' \
      -o -path '*sanssouci/*' ! -name '*.*' \) -print0; } | sort -z)

runs=(
  "--emit=feature-ir"
  "--emit=toolpath-ir"
  "--target=rs274"
  "--target=siemens-840d"
  "--target=heidenhain-tnc"
  "--target=rs274 --no-cycles"
  "--target=native --machine=hsc-3axis"
  "--emit=stepnc --machine=hsc-3axis"
)

differ=0 total=0
for f in "${inputs[@]}"; do
  for r in "${runs[@]}"; do
    total=$((total + 1))
    for side in old new; do
      bin=${!side}
      dir="$work/$side"
      mkdir -p "$dir"
      # shellcheck disable=SC2086
      (cd "$dir" && "$bin" compile "$(realpath "$OLDPWD/$f")" $r -o out >stdout 2>stderr; echo "exit $?" >status)
      cat "$dir/out" "$dir/stdout" "$dir/stderr" "$dir/status" 2>/dev/null | sed "s|$(realpath "$f")|INPUT|g" >"$dir/all"
      rm -f "$dir/out"
    done
    if ! cmp -s "$work/old/all" "$work/new/all"; then
      differ=$((differ + 1))
      echo "DIFFERS: $f $r"
      diff "$work/old/all" "$work/new/all" | head -20
    fi
  done
done
echo "$total runs, $differ differ"
[ "$differ" = 0 ]

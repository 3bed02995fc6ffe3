#!/usr/bin/env bash
# Checks the layering of docs/architecture.md: which folder may include which,
# and that no pass or backend tests a node's kind by its name. Prints every
# offending line and exits 1; run by ctest as `layering`.
set -uo pipefail
cd "$(dirname "$0")/.."

status=0
# forbid FOLDER PATTERN WHY: no file under FOLDER has a line matching PATTERN.
forbid() {
  local folder=$1 pattern=$2 why=$3 hits
  hits=$(grep -rnE --include='*.cpp' --include='*.h' --include='*.def' "$pattern" "$folder" | grep -v '^ir/motion/' || true)
  if [ -n "$hits" ]; then
    echo "layering: $why:"
    echo "$hits"
    status=1
  fi
}

forbid backends '#include "(passes|tools)/' "backends depend on ir/, not on passes/ or tools/"
forbid passes '#include "(backends|tools)/' "passes do not depend on backends/ or tools/"
forbid runtime '#include "(ir|passes|backends|tools|frontend)/' "runtime/ stands alone (support and Eigen only)"
forbid ir '#include "(passes|backends|tools|frontend|runtime|cutting)/' "ir/ depends on support/ and geom/ (ir/geom) only; ir/motion also on runtime/"
# The driver (driver/) is the library the commands and the tests share: the
# layers below include neither it nor the commands, and only tools/ has a
# command line.
for folder in support frontend geom ir passes backends runtime cutting; do
  forbid "$folder" '#include "(driver|tools)/' "$folder/ is below the driver: it includes neither driver/ nor tools/"
done
for folder in support frontend geom ir passes backends runtime cutting driver; do
  forbid "$folder" '#include <CLI/' "only tools/ parses a command line (CLI11)"
done
forbid driver '#include "tools/' "driver/ is a library: the commands (tools/) use it, not the other way"
# The core IR (ir/*.h, ir/*.cpp) has no geometry: that is ir/geom's.
hits=$(grep -nE '#include "geom/' ir/*.h ir/*.cpp || true)
if [ -n "$hits" ]; then echo "layering: the core IR does not include geom/ (ir/geom does):"; echo "$hits"; status=1; fi
# Kinds are ir::Kind enumerators; their names are for the text form and messages.
for folder in passes backends; do
  forbid "$folder" 'kindName\(\) *[!=]=|[!=]= *[a-zA-Z_.>-]*kindName\(\)|kindNamed\(' "$folder compares kinds as enumerators, not names"
done
[ "$status" = 0 ] && echo "layering: ok"
exit "$status"

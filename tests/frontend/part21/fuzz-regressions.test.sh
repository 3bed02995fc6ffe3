#!/bin/sh
# Helper of fuzz-regressions.test: $1 = folder of inputs, $2 = scratch prefix.
status=0
for f in "$1"/*; do
  [ -f "$f" ] || continue
  timeout 20 stepnc check --no-schema "$f" > /dev/null 2>&1
  rc=$?
  if [ $rc -gt 1 ]; then
    echo "FAIL: stepnc check $f exited $rc"
    status=1
    continue
  fi
  # The schema check and the whole compile path must not crash on it either.
  for cmd in "check" "compile -o $2.ir"; do
    timeout 20 stepnc $cmd "$f" > /dev/null 2>&1
    c=$?
    if [ $c -gt 2 ]; then
      echo "FAIL: stepnc $cmd $f exited $c"
      status=1
    fi
  done
  if [ $rc -eq 0 ]; then
    stepnc convert "$f" -o "$2.1.stp" > /dev/null 2>&1 &&
      stepnc convert "$2.1.stp" -o "$2.2.stp" > /dev/null 2>&1 &&
      cmp -s "$2.1.stp" "$2.2.stp" || { echo "FAIL: round trip of $f"; status=1; }
  fi
done
exit $status

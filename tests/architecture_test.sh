#!/usr/bin/env bash
# The layers of docs/architecture.md hold in the build: the committed layer graph equals the
# one CMake reports, no room reaches a layer it must not (tools/architecture/layers.py
# FORBIDDEN), and the device binary holds no solver or CHOLMOD code.
# Usage: architecture_test.sh SOURCE_DIR BIN_DIR
set -euo pipefail
src=$1
bin=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cmake -S "$src" -B "$tmp/b" -DSNAPTHREAD_SYSTEM_LCM=ON --graphviz="$tmp/deps.dot" >"$tmp/cmake.log" 2>&1 || { cat "$tmp/cmake.log"; exit 1; }
/usr/bin/python3 "$src/tools/architecture/layers.py" "$tmp/deps.dot" --forbid
/usr/bin/python3 "$src/tools/architecture/layers.py" "$tmp/deps.dot" --check "$src/docs/diagrams/layers.dot"
if [ -x "$bin/snapthread-device" ]; then
  found=$(nm -C "$bin/snapthread-device" | grep -iE 'HigherOrder|NewtonSolver|cholmod|EquilibriumTracker' | head -5 || true)
  if [ -n "$found" ]; then
    echo "snapthread-device holds solver code:"; echo "$found"; exit 1
  fi
  echo "snapthread-device: no solver, tracker or CHOLMOD symbol"
else
  echo "no snapthread-device in $bin"; exit 1
fi

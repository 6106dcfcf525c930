#!/usr/bin/env bash
# The docs kept true against the tree (label unit, well under a second):
#  - docs/scenes.md is exactly what `snapthread-sweep --print-scene-schema` prints;
#  - every relative link in README.md and docs/*.md names a file or folder that exists and,
#    with #anchor into a Markdown page, a heading of that page (GitHub's anchor rule);
#  - docs/architecture.md names every top-level folder and every CMake target.
# Usage: docs_test.sh SOURCE_DIR BIN_DIR TARGET_LIST_FILE
set -euo pipefail
src=$1
bin=$2
targets=$3
fail=0

if ! diff -u "$src/docs/scenes.md" <("$bin/snapthread-sweep" --print-scene-schema); then
  echo "docs/scenes.md differs from snapthread-sweep --print-scene-schema (regenerate: see its first lines)"
  fail=1
fi

/usr/bin/python3 "$src/tests/docs_links.py" "$src" || fail=1

for d in "$src"/*/; do
  d=$(basename "$d")
  case "$d" in build*|out|node_modules) continue ;; esac
  grep -q "\`$d/" "$src/docs/architecture.md" ||
    { echo "docs/architecture.md does not name the folder $d/ (as \`$d/...\`)"; fail=1; }
done
while read -r t; do
  [ -n "$t" ] || continue
  # A library may be named by its alias: snapthread_models as snapthread::models.
  grep -qw -- "$t" "$src/docs/architecture.md" || grep -q -- "snapthread::${t#snapthread_}\b" "$src/docs/architecture.md" ||
    { echo "docs/architecture.md does not name the CMake target $t"; fail=1; }
done <"$targets"
exit $fail

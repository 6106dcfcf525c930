#!/usr/bin/env bash
# Same bits: runs every shipped scene's sweep with every solver method, the thread3d path of
# the bench at n = 1000, and the bench's accuracy grid, with two builds' binaries,
# and compares every number but the timings. A refactor that keeps the same operations in the
# same order prints "same" on every line; any other change names the run, row and column.
#
# Usage: tools/same_bits/check.sh OLD_BIN_DIR NEW_BIN_DIR [--quick]
#   OLD_BIN_DIR / NEW_BIN_DIR: build/bin folders (snapthread-sweep, snapthread-bench).
#   --quick: fewer steps on the long rod paths (a few seconds instead of minutes).
# Exit code: 0 when every run is the same, 1 when one differs or fails, 2 for bad arguments.
set -uo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
if [ $# -lt 2 ]; then
  sed -n 2,10p "${BASH_SOURCE[0]}" >&2
  exit 2
fi
old=$(cd "$1" && pwd) || exit 2
new=$(cd "$2" && pwd) || exit 2
quick=0
[ "${3:-}" = "--quick" ] && quick=1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
failures=0

# compare NAME A B IGNORED_COLUMN_REGEX: the two CSVs, cell by cell, but the columns whose
# header matches the regex (timings).
compare() {
  python3 "$here/tools/same_bits/compare_csv.py" "$1" "$2" "$3" "$4" || failures=$((failures + 1))
}

# run_both NAME ARGS...: the sweep with both binaries (exact digits, shapes too), then compare.
run_both() {
  local name=$1
  shift
  local side
  for side in old new; do
    local bin=$old
    [ "$side" = new ] && bin=$new
    if ! "$bin/snapthread-sweep" "$@" --exact --out "$work/$name.$side.csv" \
        --shape-out "$work/$name.$side.shape.csv" 2>"$work/$name.$side.err"; then
      # A run that fails must fail the same way on both sides.
      echo "exit $?" >>"$work/$name.$side.csv"
    fi
  done
  compare "$name" "$work/$name.old.csv" "$work/$name.new.csv" '^solve_us$'
  compare "$name (shapes)" "$work/$name.old.shape.csv" "$work/$name.new.shape.csv" '^$'
}

methods=(newton newton-ls higher-order)
long_steps=2000 hockling_steps=300
((quick)) && long_steps=200 hockling_steps=60
for scene in "$here"/scenes/*.yaml; do
  base=$(basename "$scene" .yaml)
  steps=100
  case $base in
    rod_greenhill) steps=$long_steps ;;
    rod_hockling) steps=$hockling_steps ;;
  esac
  for m in "${methods[@]}"; do
    run_both "$base.$m" --scene "$scene" --path --steps "$steps" --method "$m"
  done
done
# The rod at n = 10 (its scene's default is n = 100 above).
run_both rod_greenhill.n10 --scene "$here/scenes/rod_greenhill.yaml" --path --steps 200 --set params.n=10
# The bench's path (tools/bench/path.cc): thread3d along (n - 0.5, 0.5, 0) -> (n - 0.5, 0.8, 0.2).
run_both thread3d_path.n1000 --scene "$here/scenes/thread3d_loop.yaml" --set params.n=1000 \
  --from 999.5,0.5,0 --to 999.5,0.8,0.2 --steps $((quick ? 100 : 1000)) --method higher-order

# The bench's accuracy grid (--quick): every column but rates, times and the Pareto flag
# (which ranks by rate). The scaling grid is left out: it stops growing n when a time budget
# runs out, so its rows depend on the machine's load.
for side in old new; do
  bin=$old
  [ "$side" = new ] && bin=$new
  "$bin/snapthread-bench" --quick --only accuracy --no-plot --scenes "$here/scenes" \
    --out "$work/bench.$side" >"$work/bench.$side.log" 2>&1 || echo "bench ($side) failed" >&2
done
for csv in accuracy; do
  compare "bench $csv" "$work/bench.old/$csv.csv" "$work/bench.new/$csv.csv" '(rate_hz|_us|pareto)'
done

if ((failures)); then
  echo "same_bits: $failures run(s) differ"
  exit 1
fi
echo "same_bits: every run is the same"

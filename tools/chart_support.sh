# Sourced by the chart scripts (tools/rod/charts.sh, tools/snap_ahead/chart.sh) after they
# set `here` (the source tree). chart_setup [BUILD_BIN_DIR] [OUT_DIR] sets bin (default
# $here/build/bin) and out (default $here/docs/images, made), both absolute, and work, a
# temporary folder removed when the script exits.
chart_setup() {
  bin=${1:-$here/build/bin}
  out=${2:-$here/docs/images}
  mkdir -p "$out"
  out=$(cd "$out" && pwd)
  bin=$(cd "$bin" && pwd)
  work=$(mktemp -d)
  trap 'rm -rf "$work"' EXIT
}

#!/bin/sh
# The snap-ahead chart in docs/images: snap position error, in servo ticks of
# travel, against the server's update rate (1000, 300, 100, 30 Hz), with and without
# snap-ahead, for curve2d_snap and thread3d_loop (snapthread-snap-ahead-chart: sessions
# on a fake clock, so the numbers do not depend on the machine's load). thread3d_loop's
# snaps are reached by turning the grip (45 degrees/s): its ticks of travel are ticks of
# turning. Writes docs/images/snap_ahead.png and docs/snap_ahead.csv.
# usage: tools/snap_ahead/chart.sh [BUILD_BIN_DIR] [OUT_DIR]   (gnuplot from gnuplot-nox)
set -eu
here=$(cd "$(dirname "$0")/../.." && pwd)
. "$here/tools/chart_support.sh"
chart_setup "$@"
"$bin/snapthread-snap-ahead-chart" --scene "$here/scenes/curve2d_snap.yaml" \
  --scene "$here/scenes/thread3d_loop.yaml" --rates-hz 1000,300,100,30 --out "$work/chart.csv"
cp "$work/chart.csv" "$here/docs/snap_ahead.csv"
# Mean |error| over a run's snaps, per scene, mode and rate: "rate error" rows.
for scene in curve2d_snap thread3d_loop; do
  for mode in 1 0; do
    awk -F, -v s=$scene -v m=$mode 'NR > 1 && $1 == s && $3 == m && $6 != "nan" {
        e = $6 < 0 ? -$6 : $6; sum[$2] += e; n[$2]++ }
      END { for (r in sum) printf "%s %.3f\n", r, sum[r] / n[r] }' "$work/chart.csv" |
      sort -n > "$work/${scene}_$mode.dat"
  done
done
cd "$work"
gnuplot <<GP
set terminal pngcairo size 900,560 font 'DejaVu Sans,10'
set termoption noenhanced
set output '$out/snap_ahead.png'
set title 'Snap position error vs server rate (sim-path hand: 0.05 m/s, thread3d_loop turning 45 deg/s; 1 kHz servo)'
set grid
set logscale x
set xrange [20:1500]
set xtics (30, 100, 300, 1000)
set xlabel 'server equilibrium updates per second (--max-update-hz)'
set ylabel 'mean |felt snap - true fold| (servo ticks of travel or turning)'
set key top right
plot 'curve2d_snap_1.dat' using 1:2 with linespoints lw 2 pt 7 title 'curve2d_snap, snap-ahead', \
     'curve2d_snap_0.dat' using 1:2 with linespoints lw 2 pt 6 dt 2 title 'curve2d_snap, --no-snap-ahead', \
     'thread3d_loop_1.dat' using 1:2 with linespoints lw 2 pt 5 title 'thread3d_loop, snap-ahead', \
     'thread3d_loop_0.dat' using 1:2 with linespoints lw 2 pt 4 dt 2 title 'thread3d_loop, --no-snap-ahead'
GP

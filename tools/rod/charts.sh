#!/bin/sh
# The rod's charts in docs/images, from snapthread-sweep runs:
#   rod_greenhill.png  critical twist against n beside Greenhill's 8.9868 EI/GJ, and the
#                      torque-twist curve through the buckle (n = 40);
#   rod_hockling.png   the rod just before and just after the loop snaps in, and the
#                      torque and probe along the path there and back.
# usage: tools/rod/charts.sh [BUILD_BIN_DIR] [OUT_DIR]   (gnuplot from Debian's gnuplot-nox)
set -eu
here=$(cd "$(dirname "$0")/../.." && pwd)
. "$here/tools/chart_support.sh"
chart_setup "$@"
sweep="$bin/snapthread-sweep"

# The first unstable row (a negative pivot, lambda_min < 0, or probe > 1e-4): Φ_c in rad.
: > "$work/critical.dat"
for n in 10 15 20 30 40 60; do
  "$sweep" --scene "$here/scenes/rod_greenhill.yaml" --set params.n=$n --path --steps 2000 --out "$work/gh_$n.csv"
  awk -F, -v n=$n 'NR == 1 { for (i = 1; i <= NF; ++i) c[$i] = i; next }
    $(c["step"]) > 0 && ($(c["negative_pivots"]) > 0 || $(c["lambda_min"]) < 0 || $(c["probe"]) > 1e-4) {
      printf "%d %.5f\n", n, $(c["roll_deg"]) * 3.14159265358979 / 180; exit }' "$work/gh_$n.csv" >> "$work/critical.dat"
done
"$sweep" --scene "$here/scenes/rod_hockling.yaml" --path --steps 300 --out "$work/hk.csv" --shape-out "$work/hk_shape.csv"
# The rows around the first snap: the last row before it and the row it lands on.
snap=$(awk -F, 'NR == 1 { for (i = 1; i <= NF; ++i) c[$i] = i; next } $(c["snapped"]) == 1 { print $(c["step"]); exit }' "$work/hk.csv")
land=$(awk -F, -v s="$snap" 'NR == 1 { for (i = 1; i <= NF; ++i) c[$i] = i; next }
  $(c["step"]) >= s && $(c["snapped"]) == 0 { print $(c["step"]) - 1; exit }' "$work/hk.csv")
before=$((snap - 1))
awk -F, -v s=$before '$1 == s' "$work/hk_shape.csv" > "$work/before.dat"
awk -F, -v s=$land '$1 == s' "$work/hk_shape.csv" > "$work/after.dat"

cd "$work"
gnuplot <<GP
set terminal pngcairo size 1200,500 font 'DejaVu Sans,10'
set termoption noenhanced
set datafile separator ','
set output '$out/rod_greenhill.png'
set multiplot layout 1,2 title 'rod_greenhill: clamped-clamped twist buckling (L = 1, EI = GJ = 1, EA = 1000)'
set grid
set datafile separator whitespace
set xlabel 'edges n'
set ylabel 'critical end-to-end twist (rad)'
set logscale x
set xrange [8:70]
plot 'critical.dat' using 1:2 with linespoints lw 2 pt 7 title 'discrete rod (first instability)', \
     8.9868 with lines lw 2 dt 2 title 'Greenhill: 8.9868 EI/GJ'
unset logscale x
set xrange [*:*]
set datafile separator ','
set xlabel 'roll of the grasp (degrees)'
set ylabel 'torque on the hand about the axis, -t_x (N m)'
set key top left
plot 'gh_40.csv' every ::1 using (column('roll_deg')):(-column('t_x')) with lines lw 2 title 'n = 40', \
     x * pi / 180 with lines dt 2 title 'GJ Phi / L', \
     'gh_40.csv' every ::1 using (column('roll_deg')):(column('probe') > 1e-4 ? -column('t_x') : 1/0) with lines lw 3 title 'out of line (probe > 1e-4)'
unset multiplot

set output '$out/rod_hockling.png'
set multiplot layout 1,3 title 'rod_hockling: n = 30, ends 0.9 apart, GJ = 3 EI; the loop snaps through at $(awk -F, -v s=$snap 'NR > 1 && $1 == s { printf "%.0f", $20 }' hk.csv) degrees'
set datafile separator ','
set xlabel 'y (m)'
set ylabel 'z (m)'
set size ratio -1
plot 'before.dat' using 4:5 with linespoints pt 7 ps 0.5 lw 2 title 'before the snap (row $before)', \
     'after.dat' using 4:5 with linespoints pt 7 ps 0.5 lw 2 title 'after (row $land)'
set xlabel 'x (m)'
set ylabel 'y (m)'
plot 'before.dat' using 3:4 with linespoints pt 7 ps 0.5 lw 2 title 'before', \
     'after.dat' using 3:4 with linespoints pt 7 ps 0.5 lw 2 title 'after'
set size noratio
set xlabel 'step (out 0..300, back 300..600)'
set ylabel 'torque -t_x (N m) / probe x 100 (m)'
plot 'hk.csv' every ::1 using 1:(-column('t_x')) with lines lw 2 title '-t_x', \
     'hk.csv' every ::1 using 1:(100 * column('probe')) with lines lw 2 title '100 x probe', \
     'hk.csv' every ::1 using 1:(column('snapped') == 1 ? -column('t_x') : 1/0) with points pt 7 ps 1.2 lc rgb 'red' title 'snap'
unset multiplot
GP
echo "wrote $out/rod_greenhill.png $out/rod_hockling.png"

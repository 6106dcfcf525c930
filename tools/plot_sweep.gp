# Force and shape along a snapthread-sweep CSV (gnuplot; from Debian's gnuplot-nox).
# usage: gnuplot -e "csv='sweep.csv'; out='sweep.png'; ttl='curve2d_snap'" tools/plot_sweep.gp
# Columns: step,u_x,u_y,u_z,f_x,f_y,f_z,probe,energy,residual,iterations,method,lambda_min,snapped,...
if (!exists("ttl")) ttl = csv
set terminal pngcairo size 1200,800 font 'DejaVu Sans,10'
set output out
set termoption noenhanced
set datafile separator ','
set grid
set key top left
set multiplot layout 2,2 title ttl
set xlabel 'grasp Y (model units)'
set ylabel 'force on the grasp'
plot csv every ::1 using 3:5 with lines lw 2 title 'F_x', '' every ::1 using 3:6 with lines lw 2 title 'F_y', \
     '' every ::1 using 3:($14 == 1 ? $6 : 1/0) with points pt 7 ps 1.2 lc rgb 'red' title 'snap'
set ylabel 'probe: y of the middle node'
plot csv every ::1 using 3:8 with lines lw 2 title 'probe (hysteresis loop)', \
     '' every ::1 using 3:($14 == 1 ? $8 : 1/0) with points pt 7 ps 1.2 lc rgb 'red' title 'snap'
set xlabel 'step'
set ylabel 'smallest eigenvalue of E_xx'
plot csv every ::1 using 1:13 with lines lw 2 title 'lambda_min'
set ylabel 'iterations per update'
plot csv every ::1 using 1:11 with impulses title 'iterations'
unset multiplot

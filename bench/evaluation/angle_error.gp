# Joint-angle error over time on the smooth trajectory (run_evaluation.sh passes
# datadir and outfile): |error| on a log scale, one point per tracked frame (frames
# without both bodies leave gaps), tracked with the calibrated and with the true model.
set terminal pngcairo size 1000,650 noenhanced font ",10"
set output outfile
set multiplot layout 2,1 title "Joint-angle error vs ground truth (smooth motion; acceptance 0.05 deg dashed)"
set grid
set logscale y
set yrange [1e-4:300]
set format y "%g"
set xlabel "time [s]"
set ylabel "shoulder |geodesic error| [deg]"
plot datadir."/plot_cal_shoulder.dat" using 1:(abs($2)) with points pt 7 ps 0.35 title "calibrated model", \
     datadir."/plot_true_shoulder.dat" using 1:(abs($2)) with points pt 6 ps 0.35 title "true model", \
     0.05 with lines dt 2 lc "black" notitle
set ylabel "elbow |angle error| [deg]"
plot datadir."/plot_cal_elbow.dat" using 1:(abs($2)) with points pt 7 ps 0.35 title "calibrated model", \
     datadir."/plot_true_elbow.dat" using 1:(abs($2)) with points pt 6 ps 0.35 title "true model", \
     0.05 with lines dt 2 lc "black" notitle
unset multiplot

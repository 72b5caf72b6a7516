# Joint angles over the viewpoint sequence (Table 1B), as deviations from their means:
# the joints are fixed, so every variation is measurement error. run_evaluation.sh
# passes datadir and outfile.
set terminal pngcairo size 1000,600 noenhanced font ",10"
set output outfile
f_sh = datadir."/views_shoulder.dat"
f_el = datadir."/views_elbow.dat"
stats f_sh using 2 name "A0" nooutput
stats f_sh using 3 name "A1" nooutput
stats f_sh using 4 name "A2" nooutput
stats f_el using 2 name "E" nooutput
set multiplot layout 2,1 title "Joint angles minus their mean while the viewpoint changes (joints fixed)"
set grid
set xlabel "frame"
set ylabel "shoulder Euler angles [deg]"
plot f_sh using 1:($2 - A0_mean) with points pt 7 ps 0.2 title "a0", \
     f_sh using 1:($3 - A1_mean) with points pt 7 ps 0.2 title "a1", \
     f_sh using 1:($4 - A2_mean) with points pt 7 ps 0.2 title "a2"
set ylabel "elbow angle [deg]"
plot f_el using 1:($2 - E_mean) with points pt 7 ps 0.2 title "angle"
unset multiplot

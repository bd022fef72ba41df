# Written by clearway bench: what accuracy costs in time. Run: gnuplot plots.gp
set terminal pngcairo noenhanced size 1000,650 font ',10'
set grid
set key outside right top
set logscale x
$mm0 << EOD
55.1126 0 0.01
51.7066 0 0.001
53.6376 0 0.0001
EOD
$mm1 << EOD
12.9585 0.0108333 0.05
43.984 0.000833333 0.01
371.811 0 0.001
EOD
$mm2 << EOD
119.021 0.0108333 0.05
365.716 0.000833333 0.01
2845.86 0 0.001
EOD
$mf0 << EOD
55.1126 0.104167 0.01
51.7066 0.0166667 0.001
53.6376 0.00333333 0.0001
EOD
$mf1 << EOD
12.9585 0 0.05
43.984 0 0.01
371.811 0 0.001
EOD
$mf2 << EOD
119.021 0 0.05
365.716 0 0.01
2845.86 0 0.001
EOD
set terminal pngcairo noenhanced size 1400,600 font ',10'
set output 'motions.png'
set multiplot layout 1,2 title 'Motion checks: what each mode misses and adds, against time per motion (labels: contact distance in m, or resolution as a fraction of the extent)'
set xlabel 'us per motion'
set yrange [-0.002:*]
set key inside right top
set title 'missed collisions (dense reference collides, mode says free)'
set ylabel 'missed-collision rate'
plot $mm0 using 1:2 with linespoints pt 7 title 'clearway certified', $mm0 using 1:2:3 with labels offset 0.6,0.6 font ',7' notitle, $mm1 using 1:2 with linespoints pt 7 title 'clearway sampled', $mm1 using 1:2:3 with labels offset 0.6,0.6 font ',7' notitle, $mm2 using 1:2 with linespoints pt 7 title 'fcl sampled', $mm2 using 1:2:3 with labels offset 0.6,0.6 font ',7' notitle
set title 'false alarms (reference free, mode says collision)'
set ylabel 'false-alarm rate'
plot $mf0 using 1:2 with linespoints pt 7 title 'clearway certified', $mf0 using 1:2:3 with labels offset 0.6,0.6 font ',7' notitle, $mf1 using 1:2 with linespoints pt 7 title 'clearway sampled', $mf1 using 1:2:3 with labels offset 0.6,0.6 font ',7' notitle, $mf2 using 1:2 with linespoints pt 7 title 'fcl sampled', $mf2 using 1:2:3 with labels offset 0.6,0.6 font ',7' notitle
unset multiplot

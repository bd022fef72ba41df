# Written by clearway bench: what accuracy costs in time. Run: gnuplot plots.gp
set terminal pngcairo noenhanced size 1000,650 font ',10'
set grid
set key outside right top
set logscale x
$np0 << EOD
371.853 0.089113 0.1
475.3 0.0131395 0.01
622.295 0.00069715 0.001
606.248 9.54365e-05 0.0001
741.588 8.07513e-07 1e-06
948.377 1.47658e-09 1e-09
EOD
$np1 << EOD
1194 0.165904 0.1
1503.69 0.0285762 0.01
1649.65 0.00434854 0.001
1779.17 0.00291626 0.0001
2069.97 0.00291626 1e-06
2608.79 0.00291626 1e-09
EOD
$np2 << EOD
761.595 2.08461 0.1
983.062 0.619448 0.01
1196.5 0.421285 0.001
1268.22 0.00786048 0.0001
1622.62 8.04717e-05 1e-06
2145.51 4.84065e-07 1e-09
EOD
set output 'narrowphase.png'
set title 'GJK distance: worst error against time per query (labels: tolerance; 1e-17 means exact)'
set xlabel 'ns per query'
set ylabel 'max |distance error| (m)'
set logscale y
set format y '1e%T'
plot $np0 using 1:2 with linespoints pt 7 title 'clearway distance', $np0 using 1:2:3 with labels offset 0.6,0.6 font ',7' notitle, $np1 using 1:2 with linespoints pt 7 title 'fcl-indep distance', $np1 using 1:2:3 with labels offset 0.6,0.6 font ',7' notitle, $np2 using 1:2 with linespoints pt 7 title 'fcl-libccd distance', $np2 using 1:2:3 with labels offset 0.6,0.6 font ',7' notitle
unset logscale y
set format y '%g'
$st0 << EOD
7769.85 0 0
EOD
$st1 << EOD
3467.05 0.04 0
EOD
$st2 << EOD
50723.8 0 0
EOD
set output 'states.png'
set title 'One state: wrong verdicts against time per state'
set xlabel 'ns per state'
set ylabel 'wrong-verdict rate (against exact meshes)'
set yrange [-0.01:*]
plot $st0 using 1:2 with linespoints pt 7 title 'clearway mesh', $st0 using 1:2:3 with labels offset 0.6,0.6 font ',7' notitle, $st1 using 1:2 with linespoints pt 7 title 'clearway hull', $st1 using 1:2:3 with labels offset 0.6,0.6 font ',7' notitle, $st2 using 1:2 with linespoints pt 7 title 'fcl obbrss', $st2 using 1:2:3 with labels offset 0.6,0.6 font ',7' notitle
set yrange [*:*]
$mm0 << EOD
563.955 0 0.01
966.398 0 0.001
904.019 0 0.0001
EOD
$mm1 << EOD
9.74225 0.0108333 0.05
32.1938 0.000833333 0.01
260.417 0 0.001
EOD
$mm2 << EOD
92.767 0.0108333 0.05
284.705 0.000833333 0.01
2220.16 0 0.001
EOD
$mf0 << EOD
563.955 0.126667 0.01
966.398 0.0183333 0.001
904.019 0.00416667 0.0001
EOD
$mf1 << EOD
9.74225 0 0.05
32.1938 0 0.01
260.417 0 0.001
EOD
$mf2 << EOD
92.767 0 0.05
284.705 0 0.01
2220.16 0 0.001
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

# Written by clearway audit: the link-pair matrix of panda
set terminal pngcairo noenhanced size 740,740 font ',9'
set output 'benchmarks/results/audit/panda.png'
set title "Self-collision audit of panda: fraction of samples colliding\nA adjacent, D default, Al always, N never, N* never but within 1 mm"
set size ratio -1
set xrange [-0.5:10.5]
set yrange [-0.5:10.5]
set xtics ('panda_link0' 0, 'panda_link1' 1, 'panda_link2' 2, 'panda_link3' 3, 'panda_link4' 4, 'panda_link5' 5, 'panda_link6' 6, 'panda_link7' 7, 'panda_hand' 8, 'panda_leftfinger' 9, 'panda_rightfinger' 10) rotate by 60 right
set ytics ('panda_link0' 0, 'panda_link1' 1, 'panda_link2' 2, 'panda_link3' 3, 'panda_link4' 4, 'panda_link5' 5, 'panda_link6' 6, 'panda_link7' 7, 'panda_hand' 8, 'panda_leftfinger' 9, 'panda_rightfinger' 10)
set logscale cb
set cbrange [1e-5:1]
set cblabel 'colliding fraction'
set palette defined (0 '#fff7bc', 0.5 '#fe9929', 1 '#cc4c02')
set key off
set grid front
$sampled << EOD
0 5 0.01332
0 6 0.01512
0 7 0.00959
0 8 0.01166
0 9 0.00309
0 10 0.00328
1 5 0.01585
1 6 0.01035
1 7 0.00734
1 8 0.01138
1 9 0.00343
1 10 0.00332
2 5 0.00642
2 6 0.00172
2 7 0.00258
2 8 0.00627
2 9 0.00246
2 10 0.00245
5 9 0.00834
5 10 0.01098
EOD
$never << EOD
0 2 0
0 3 0
0 4 0
1 3 0
1 4 0
2 4 0
3 5 0
3 6 0
3 7 0
3 8 0
3 9 0
3 10 0
4 6 0
4 7 0
4 8 0
4 9 0
4 10 0
6 8 0
6 9 0
6 10 0
7 9 0
7 10 0
EOD
$fixed << EOD
0 1
1 2
2 3
3 4
4 5
5 6
5 7
5 8
6 7
7 8
8 9
8 10
9 10
EOD
$labels << EOD
0 1 A
0 2 N
0 3 N
0 4 N
1 2 A
1 3 N
1 4 N
2 3 A
2 4 N
3 4 A
3 5 N
3 6 N
3 7 N
3 8 N
3 9 N
3 10 N
4 5 A
4 6 N
4 7 N
4 8 N
4 9 N
4 10 N
5 6 A
5 7 D
5 8 D
6 7 A
6 8 N
6 9 N
6 10 N
7 8 A
7 9 N
7 10 N
8 9 A
8 10 A
9 10 D
EOD
plot $sampled using 1:2:(0.5):(0.5):3 with boxxyerror fs solid 1.0 noborder lc palette, $never using 1:2:(0.5):(0.5):($3 > 0 ? 0x2e7d32 : 0xa5d6a7) with boxxyerror fs solid 1.0 noborder lc rgb variable, $fixed using 1:2:(0.5):(0.5) with boxxyerror fs solid 1.0 noborder lc rgb '#bdbdbd', $labels using 1:2:3 with labels font ',7'

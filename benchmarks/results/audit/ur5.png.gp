# Written by clearway audit: the link-pair matrix of ur5_robotiq85
set terminal pngcairo noenhanced size 1060,1060 font ',9'
set output 'benchmarks/results/audit/ur5.png'
set title "Self-collision audit of ur5_robotiq85: fraction of samples colliding\nA adjacent, D default, Al always, N never, N* never but within 1 mm"
set size ratio -1
set xrange [-0.5:18.5]
set yrange [-0.5:18.5]
set xtics ('box_link' 0, 'base_link' 1, 'shoulder_link' 2, 'upper_arm_link' 3, 'forearm_link' 4, 'wrist_1_link' 5, 'wrist_2_link' 6, 'wrist_3_link' 7, 'ee_link' 8, 'fts_robotside' 9, 'robotiq_85_base_link' 10, 'robotiq_85_left_knuckle_link' 11, 'robotiq_85_left_finger_link' 12, 'robotiq_85_left_inner_knuckle_link' 13, 'robotiq_85_left_finger_tip_link' 14, 'robotiq_85_right_inner_knuckle_link' 15, 'robotiq_85_right_finger_tip_link' 16, 'robotiq_85_right_knuckle_link' 17, 'robotiq_85_right_finger_link' 18) rotate by 60 right
set ytics ('box_link' 0, 'base_link' 1, 'shoulder_link' 2, 'upper_arm_link' 3, 'forearm_link' 4, 'wrist_1_link' 5, 'wrist_2_link' 6, 'wrist_3_link' 7, 'ee_link' 8, 'fts_robotside' 9, 'robotiq_85_base_link' 10, 'robotiq_85_left_knuckle_link' 11, 'robotiq_85_left_finger_link' 12, 'robotiq_85_left_inner_knuckle_link' 13, 'robotiq_85_left_finger_tip_link' 14, 'robotiq_85_right_inner_knuckle_link' 15, 'robotiq_85_right_finger_tip_link' 16, 'robotiq_85_right_knuckle_link' 17, 'robotiq_85_right_finger_link' 18)
set logscale cb
set cbrange [1e-5:1]
set cblabel 'colliding fraction'
set palette defined (0 '#fff7bc', 0.5 '#fe9929', 1 '#cc4c02')
set key off
set grid front
$sampled << EOD
0 3 0.4343
0 4 0.3441
0 5 0.20295
0 6 0.20375
0 7 0.1805
0 8 0.13975
0 9 0.1729
0 10 0.16815
0 11 0.1163
0 12 0.1152
0 13 0.12165
0 14 0.10505
0 15 0.1201
0 16 0.10605
0 17 0.11605
0 18 0.1158
1 3 0.0388
1 4 0.04385
1 5 0.0227
1 6 0.0149
1 7 0.0091
1 8 0.0018
1 9 0.01025
1 10 0.0107
1 11 0.003
1 12 0.003
1 13 0.0029
1 14 0.00145
1 15 0.00365
1 16 0.00155
1 17 0.0031
1 18 0.00315
2 4 0.08155
2 5 0.06935
2 6 0.0376
2 7 0.02095
2 8 0.0042
2 9 0.02065
2 10 0.01935
2 11 0.00435
2 12 0.00435
2 13 0.0047
2 14 0.0023
2 15 0.00545
2 16 0.00215
2 17 0.00445
2 18 0.00445
3 5 0.0895
3 6 0.0822
3 7 0.05445
3 8 0.0119
3 9 0.0404
3 10 0.0255
3 11 0.0075
3 12 0.0087
3 13 0.01
3 14 0.00755
3 15 0.0091
3 16 0.00595
3 17 0.00725
3 18 0.008
4 6 0.046
4 7 0.08125
4 8 0.0217
4 9 0.0978
4 10 0.08715
4 11 0.01435
4 12 0.0137
4 13 0.01665
4 14 0.00815
4 15 0.01695
4 16 0.0087
4 17 0.01535
4 18 0.0146
EOD
$never << EOD
0 2 0
5 7 0
5 8 0
5 9 0
5 10 0
5 11 0
5 12 0
5 13 0
5 14 0
5 15 0
5 16 0
5 17 0
5 18 0
6 8 0
6 9 0
6 10 0
6 11 0
6 12 0
6 13 0
6 14 0
6 15 0
6 16 0
6 17 0
6 18 0
7 10 0
7 11 0
7 12 0
7 13 0
7 14 0
7 15 0
7 16 0
7 17 0
7 18 0
8 10 0
8 11 0
8 12 0
8 13 0
8 14 0
8 15 0
8 16 0
8 17 0
8 18 0
9 11 0
9 12 0
9 13 0
9 14 0
9 15 0
9 16 0
9 17 0
9 18 0
10 12 0
10 14 0
10 16 0
10 18 0
11 13 0
11 14 0
11 15 0
11 16 0
11 17 0
11 18 0
12 13 0
12 15 0
12 16 0
12 17 0
12 18 0
13 15 0
13 16 0
13 17 0
13 18 0
14 15 0
14 16 0
14 17 0
14 18 0
15 17 0
15 18 0
16 17 0
EOD
$fixed << EOD
0 1
1 2
2 3
3 4
4 5
5 6
6 7
7 8
7 9
8 9
9 10
10 11
10 13
10 15
10 17
11 12
12 14
13 14
15 16
16 18
17 18
EOD
$labels << EOD
0 1 A
0 2 N
1 2 A
2 3 A
3 4 A
4 5 A
5 6 A
5 7 N
5 8 N
5 9 N
5 10 N
5 11 N
5 12 N
5 13 N
5 14 N
5 15 N
5 16 N
5 17 N
5 18 N
6 7 A
6 8 N
6 9 N
6 10 N
6 11 N
6 12 N
6 13 N
6 14 N
6 15 N
6 16 N
6 17 N
6 18 N
7 8 A
7 9 D
7 10 N
7 11 N
7 12 N
7 13 N
7 14 N
7 15 N
7 16 N
7 17 N
7 18 N
8 9 A
8 10 N
8 11 N
8 12 N
8 13 N
8 14 N
8 15 N
8 16 N
8 17 N
8 18 N
9 10 A
9 11 N
9 12 N
9 13 N
9 14 N
9 15 N
9 16 N
9 17 N
9 18 N
10 11 A
10 12 N
10 13 A
10 14 N
10 15 A
10 16 N
10 17 A
10 18 N
11 12 A
11 13 N
11 14 N
11 15 N
11 16 N
11 17 N
11 18 N
12 13 N
12 14 D
12 15 N
12 16 N
12 17 N
12 18 N
13 14 A
13 15 N
13 16 N
13 17 N
13 18 N
14 15 N
14 16 N
14 17 N
14 18 N
15 16 A
15 17 N
15 18 N
16 17 N
16 18 D
17 18 A
EOD
plot $sampled using 1:2:(0.5):(0.5):3 with boxxyerror fs solid 1.0 noborder lc palette, $never using 1:2:(0.5):(0.5):($3 > 0 ? 0x2e7d32 : 0xa5d6a7) with boxxyerror fs solid 1.0 noborder lc rgb variable, $fixed using 1:2:(0.5):(0.5) with boxxyerror fs solid 1.0 noborder lc rgb '#bdbdbd', $labels using 1:2:3 with labels font ',7'

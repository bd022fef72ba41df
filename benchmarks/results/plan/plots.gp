# Written by clearway bench: what accuracy costs in time. Run: gnuplot plots.gp
set terminal pngcairo noenhanced size 1000,650 font ',10'
set grid
set key outside right top
set logscale x

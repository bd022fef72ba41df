# Error against time per query, log–log: one curve per method and shape family (tolerance 1e-1 … 1e-7
# along each curve). Reads the CSV files written by bench_narrowphase.
# Usage: gnuplot -e "dir='benchmarks/results'" benchmarks/plot_narrowphase.gp
if (!exists("dir")) dir = "benchmarks/results"
set datafile separator ","
set datafile missing ""
set terminal pngcairo noenhanced size 1500,700 font ",10"
set logscale xy
set grid
set format y "1e%T"
set key inside right bottom spacing 0.9 font ",8" box opaque
set yrange [1e-16:1]
floor = 1e-16   # an error of exactly 0 (GJK ends on the exact vertex of a polytope) is drawn here
clip(e) = (e > floor ? e : floor)

set output dir."/narrowphase_distance.png"
set multiplot layout 1,2 title "GJK distance: mean |error| vs mean time per query (tolerance 1e-1 … 1e-7; errors of 0 drawn at 1e-16)"
methods = "clearway fcl_indep fcl_libccd"
hulls = "hull16 hull64 hull256"
prims = "box-box sphere-box capsule-capsule cylinder-cone"
sel(f, m) = (strcol(1) eq f && strcol(2) eq m && $3 > 1e-9)
set xlabel "time per query (ns)"
set ylabel "mean |distance − reference| (m)"
set title "convex hulls"
plot for [i=1:words(hulls)] for [j=1:words(methods)] dir."/narrowphase_distance.csv" \
     using (sel(word(hulls,i), word(methods,j)) ? $4 : NaN):(clip($6)) \
     with linespoints lc i dt j pt (4*j-2) title word(hulls,i)." ".word(methods,j)
set title "primitive pairs (FCL: closed forms for sphere-box and capsule-capsule)"
plot for [i=1:words(prims)] for [j=1:words(methods)] dir."/narrowphase_distance.csv" \
     using (sel(word(prims,i), word(methods,j)) ? $4 : NaN):(clip($6)) \
     with linespoints lc i dt j pt (4*j-2) title word(prims,i)." ".word(methods,j)
unset multiplot

set output dir."/narrowphase_raycast.png"
set terminal pngcairo noenhanced size 1000,700 font ",10"
set key inside left bottom
set title "GJK ray cast: mean |t − exact| vs mean time per query (tolerance 1e-1 … 1e-7)"
set ylabel "mean |t − exact| (m); van den Bergen 2004: tolerance"
rshapes = "hull16 hull64 hull256 box capsule cylinder cone"
plot for [i=1:words(rshapes)] dir."/narrowphase_raycast.csv" \
     using (strcol(1) eq word(rshapes,i) ? $4 : NaN):(clip($6)) with linespoints lc i pt 7 title word(rshapes,i), \
     dir."/narrowphase_raycast.csv" using (strcol(1) eq "hull16" ? 1000*$12 : NaN):3 \
     with linespoints lc rgb "black" dt 2 pt 5 title "van den Bergen 2004 (2.6 GHz), at its tolerance"

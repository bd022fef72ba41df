#!/usr/bin/env bash
# Builds bench_narrowphase optimised (-O2, its own build directory), runs it at low priority, and draws
# the plots. Results: benchmarks/results/narrowphase_{distance,raycast,intersect}.csv and *.png.
# Run on a quiet machine: the times are medians, but a loaded machine still shifts them.
JOBS=${JOBS:-1} source "$(dirname "$0")/build_bench.sh" bench_narrowphase
nice -n 10 "$BUILD/benchmarks/bench_narrowphase" --out "$OUT" "$@" | tee "$OUT/narrowphase_table.txt"
gnuplot -e "dir='$OUT'" benchmarks/plot_narrowphase.gp
echo "wrote $OUT/narrowphase_*.csv, narrowphase_table.txt, narrowphase_distance.png, narrowphase_raycast.png"

#!/usr/bin/env bash
# Builds bench_narrowphase optimised (-O2, its own build directory), runs it at low priority, and draws
# the plots. Results: benchmarks/results/narrowphase_{distance,raycast,intersect}.csv and *.png.
# Run on a quiet machine: the times are medians, but a loaded machine still shifts them.
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD=${BUILD:-/tmp/build-bench}
OUT=${OUT:-benchmarks/results}
nice -n 10 cmake -S . -B "$BUILD" -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_FLAGS_RELEASE="-O2 -DNDEBUG" \
  -DCLEARWAY_BUILD_TESTS=OFF -DCLEARWAY_BUILD_TOOLS=OFF -DCLEARWAY_BUILD_BENCHMARKS=ON >/dev/null
nice -n 10 cmake --build "$BUILD" -j1 --target bench_narrowphase
mkdir -p "$OUT"
nice -n 10 "$BUILD/benchmarks/bench_narrowphase" --out "$OUT" "$@" | tee "$OUT/narrowphase_table.txt"
gnuplot -e "dir='$OUT'" benchmarks/plot_narrowphase.gp
echo "wrote $OUT/narrowphase_*.csv, narrowphase_table.txt, narrowphase_distance.png, narrowphase_raycast.png"

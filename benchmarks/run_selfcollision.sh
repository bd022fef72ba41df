#!/usr/bin/env bash
# Builds bench_selfcollision optimised (-O2, its own build directory) and runs it on the shared Panda and
# UR5 (10,000 random states each, fixed seed), Clearway mesh/hull against FCL OBBRSS/OBB in one run.
# Results: benchmarks/results/selfcollision.csv and selfcollision_table.txt.
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD=${BUILD:-/tmp/build-bench}
OUT=${OUT:-benchmarks/results}
nice -n 10 cmake -S . -B "$BUILD" -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_FLAGS_RELEASE="-O2 -DNDEBUG" \
  -DCLEARWAY_BUILD_TESTS=OFF -DCLEARWAY_BUILD_TOOLS=OFF -DCLEARWAY_BUILD_BENCHMARKS=ON >/dev/null
nice -n 10 cmake --build "$BUILD" -j2 --target bench_selfcollision
mkdir -p "$OUT"
nice -n 10 "$BUILD/benchmarks/bench_selfcollision" --csv "$OUT/selfcollision.csv" "$@" | tee "$OUT/selfcollision_table.txt"

#!/usr/bin/env bash
# Builds bench_selfcollision optimised (-O2, its own build directory) and runs it on the shared Panda and
# UR5 (10,000 random states each, fixed seed), Clearway mesh/hull against FCL OBBRSS/OBB in one run.
# Results: benchmarks/results/selfcollision.csv and selfcollision_table.txt.
source "$(dirname "$0")/build_bench.sh" bench_selfcollision
nice -n 10 "$BUILD/benchmarks/bench_selfcollision" --csv "$OUT/selfcollision.csv" "$@" | tee "$OUT/selfcollision_table.txt"

#!/usr/bin/env bash
# Builds the clearway tool optimised (-O2, its own build directory) and runs `clearway bench all` on the
# shared problems: GJK distance by tolerance, one state by mode, motions by mode and tolerance, and
# RRTConnect with each checker, Clearway and FCL side by side, into benchmarks/results/bench/
# (results.csv, summary.csv, table.txt, narrowphase.png, states.png, motions.png, plan/*.log).
# Arguments go to clearway bench (e.g. --count 50 for a quick run). Takes about 15 minutes on 2 cores.
source "$(dirname "$0")/build_bench.sh" clearway_tool
nice -n 10 "$BUILD/clearway" bench all --count 200 --plan-runs 5 --plan-time 20 --out "$OUT/bench" "$@"

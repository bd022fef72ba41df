#!/usr/bin/env bash
# Builds bench_scene optimised (-O2, its own build directory) and runs it on the shared problems:
# per-state environment / scene / clearance checks against FCL (scene.csv, scene_table.txt), and start
# and goal of all 60 problems in both forms against FCL (start_goal.txt). Motion checks and planning:
# benchmarks/run_bench.sh.
source "$(dirname "$0")/build_bench.sh" bench_scene
nice -n 10 "$BUILD/benchmarks/bench_scene" --start-goal > "$OUT/start_goal.txt"
tail -1 "$OUT/start_goal.txt"
nice -n 10 "$BUILD/benchmarks/bench_scene" --states 1000 --problems 1 --csv "$OUT/scene.csv" "$@" | tee "$OUT/scene_table.txt"

#!/usr/bin/env bash
# Builds bench_scene and bench_motion optimised (-O2, their own build directory) and runs them on the shared
# problems: per-state environment / scene / clearance checks against FCL (scene.csv, scene_table.txt), start
# and goal of all 60 problems in both forms against FCL (start_goal.txt), and motion checks per segment
# (motion.csv, motion_table.txt), and RRTConnect with each checker (plan.csv, plan_table.txt, OMPL benchmark
# logs in plan_logs/). Takes about 15 minutes on 2 cores.
source "$(dirname "$0")/build_bench.sh" bench_scene bench_motion bench_plan
nice -n 10 "$BUILD/benchmarks/bench_scene" --start-goal > "$OUT/start_goal.txt"
tail -1 "$OUT/start_goal.txt"
nice -n 10 "$BUILD/benchmarks/bench_scene" --states 1000 --problems 1 --csv "$OUT/scene.csv" "$@" | tee "$OUT/scene_table.txt"
nice -n 10 "$BUILD/benchmarks/bench_motion" --motions 200 --problems 2 --csv "$OUT/motion.csv" | tee "$OUT/motion_table.txt"
nice -n 10 "$BUILD/benchmarks/bench_plan" --problems 1 --runs 5 --time 20 --logs "$OUT/plan_logs" --csv "$OUT/plan.csv" | tee "$OUT/plan_table.txt"

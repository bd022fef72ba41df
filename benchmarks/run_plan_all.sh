#!/usr/bin/env bash
# `clearway plan` on every shared problem, in both forms (primitive obstacles and OctoMap): RRTConnect with
# Clearway's validity checker and certified motion validator, the final path re-certified segment by
# segment. One line per scene in benchmarks/results/plan_all.txt: the exit status (0 solved and certified,
# 1 no path or a start/goal in collision, 2 bad input), and clearway plan's own summary line or reason.
# Usage: benchmarks/run_plan_all.sh [--time S] [--seed N]   (defaults: 30 s, seed 1)
source "$(dirname "$0")/build_bench.sh" clearway_tool
SHARED=${SHARED:-../shared}
time_limit=30
seed=1
while [ $# -gt 0 ]; do
  case "$1" in
    --time) time_limit=$2; shift 2 ;;
    --seed) seed=$2; shift 2 ;;
    *) echo "usage: run_plan_all.sh [--time S] [--seed N]" >&2; exit 2 ;;
  esac
done
report=$OUT/plan_all.txt
echo "# clearway plan on every shared scene: RRTConnect, --time $time_limit --seed $seed; $(date -u '+%F %H:%M UTC')" >"$report"
solved=0 total=0
for scene in "$SHARED"/scenes/*/*.yaml; do
  total=$((total + 1))
  set +e
  err=$(nice -n 10 "$BUILD/clearway" plan "$scene" --time "$time_limit" --seed "$seed" 2>&1 >/dev/null)
  status=$?
  set -e
  [ "$status" = 0 ] && solved=$((solved + 1))
  line=$(printf '%s\n' "$err" | grep -E '^planner |^clearway plan: ' | head -1)
  printf '%s %d %s\n' "$(basename "$scene")" "$status" "$line" | tee -a "$report"
done
echo "# $solved of $total scenes solved and certified" | tee -a "$report"

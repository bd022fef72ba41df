#!/usr/bin/env bash
# Instructions of a state's and a motion's phases, which do not depend on the machine's load (the wall
# clock of a shared 2-core machine does): bench_breakdown's one round under callgrind, the Highway targets
# valgrind cannot run hidden (callgrind_targets.cpp). Prints, per scene, the instructions of each phase.
# usage: bash benchmarks/run_callgrind.sh BUILD_DIR [states|motions] SCENE.yaml...
#   (BUILD_DIR: a Release build with benchmarks; needs valgrind)
set -euo pipefail
BUILD=$(cd "$1" && pwd); WHAT=$2; shift 2
HERE=$(cd "$(dirname "$0")" && pwd)
STUB=$BUILD/callgrind_targets.so
[ "$STUB" -nt "$HERE/callgrind_targets.cpp" ] ||
  "${CXX:-c++}" -O2 -shared -fPIC -o "$STUB" "$HERE/callgrind_targets.cpp" -ldl
case $WHAT in
  states) PHASES=(--toggle-collect='*phaseFreeStates*' --toggle-collect='*phaseCollidingStates*') ;;
  motions) PHASES=(--toggle-collect='*phaseFreeMotions*' --toggle-collect='*phaseCollidingMotions*') ;;
  *) echo "usage: run_callgrind.sh BUILD_DIR [states|motions] SCENE.yaml..." >&2; exit 2 ;;
esac
OUT=$(mktemp -d "${TMPDIR:-/tmp}/clearway-callgrind.XXXXXX")
trap 'rm -rf "$OUT"' EXIT
for scene in "$@"; do
  LD_PRELOAD=$STUB valgrind --tool=callgrind --callgrind-out-file="$OUT/cg" "${PHASES[@]}" \
    "$BUILD/benchmarks/bench_breakdown" --once --states 3000 "$scene" >"$OUT/log" 2>&1
  # (bench_breakdown's own counts; its times under valgrind mean nothing and are dropped)
  echo "$(basename "$scene"): $(grep -E '^  (free state|motions)' "$OUT/log" | sed -E 's/ *= .*//; s/ [0-9]+ ns( alone)?,?//g; s/free state \(([0-9]+)\):/free states \1;/; s/motions \(([0-9]+), mixed\):;/motions \1:/; s/  */ /g' | tr '\n' ' ')"
  callgrind_annotate --inclusive=yes "$OUT/cg" | grep -E '::phase[A-Za-z]+\(' |
    sed -E 's/^ *([0-9,]+) .*::(phase[A-Za-z]+)\(.*/  \2 \1 instructions/'
done

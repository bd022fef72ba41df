#!/usr/bin/env bash
# Builds the libFuzzer targets of fuzz/ (clang, ASan + UBSan, -O1 -g, in build-fuzz/) and runs each for
# SECONDS (default 20) on a copy of its seeds: fuzz/corpus/<target>/, our own robots, meshes and scenes
# of that kind, and ../shared/bad-inputs/ ($CLEARWAY_SHARED/bad-inputs) when it is there.
#   bash scripts/fuzz.sh [SECONDS] [TARGET...]      e.g.  bash scripts/fuzz.sh 3600 mesh_dae
# FUZZ_SEED=N fixes libFuzzer's random seed (CI does, so that a run can be replayed; 0: a new one).
# A crash, sanitizer report, undocumented exception, timeout (10 s) or memory blow-up (2 GB) is a
# finding: the input is kept as build-fuzz/crashes/<target>-crash-* (or -timeout-, -oom-, -leak-) and
# printed in base64, the log as build-fuzz/logs/<target>.log, and the script exits 1 after running the
# other targets. A timeout counts only if the input, run again alone, times out again.
# Interesting inputs found on the way stay in build-fuzz/corpus/<target>/ for the next run.
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
SECONDS_PER_TARGET=${1:-20}
shift || true
BUILD=${BUILD:-build-fuzz}
SHARED=${CLEARWAY_SHARED:-$ROOT/../shared}
bash scripts/install-deps.sh >/dev/null

CC=clang CXX=clang++ cmake -S . -B "$BUILD" -DCLEARWAY_BUILD_FUZZERS=ON -DBUILD_SHARED_LIBS=OFF \
  -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g" \
  -DCLEARWAY_BUILD_TESTS=OFF -DCLEARWAY_BUILD_TOOLS=OFF -DCLEARWAY_BUILD_BENCHMARKS=OFF -DCLEARWAY_BUILD_OMPL=OFF -DCLEARWAY_BUILD_PYTHON=OFF >/dev/null
cmake --build "$BUILD" -j2 --target clearway_fuzzers

targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(urdf mesh_stl mesh_obj mesh_dae mesh_ply scene octomap query state_line motion_line bench_merge scene_attached scene_edits)

# Seeds of our own beyond fuzz/corpus/, by target (files as they are; the URDF target's SRDF after a
# separator line).
seed() {
  local target=$1 dir=$2
  case "$target" in
    urdf)
      for f in robots/*/*.urdf; do cp "$f" "$dir/"; done
      { cat robots/arm6/arm6.urdf; printf '\n@@SRDF@@\n'; cat robots/arm6/arm6.srdf; } >"$dir/arm6_with_srdf.urdf" ;;
    mesh_*) find robots -name "*.${target#mesh_}" -exec cp {} "$dir/" \; ;;
    scene | scene_attached) cp robots/scenes/*.yaml "$dir/" ;;
    query) cp robots/demo/queries.jsonl "$dir/" ;;
  esac
  # Inputs that once broke the tool (../shared is development data, never copied into the repository).
  if [ -d "$SHARED/bad-inputs" ]; then
    local pattern=''
    case "$target" in
      urdf) pattern='*.urdf' ;; mesh_*) pattern="*.${target#mesh_}" ;; scene | scene_attached) pattern='*.yaml' ;;
      octomap) pattern='*.[bo]t' ;; query) pattern='*.jsonl' ;; state_line) pattern='state*.txt' ;;
      motion_line) pattern='motions*.txt' ;;
    esac
    [ -n "$pattern" ] || return 0
    find "$SHARED/bad-inputs" -name "$pattern" -type f | while read -r f; do
      cp "$f" "$dir/bad-$(basename "$(dirname "$f")")-$(basename "$f")"
    done
  fi
}

mkdir -p "$BUILD/crashes" "$BUILD/logs"
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1} UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1}
failed=()
for target in "${targets[@]}"; do
  exe=$BUILD/fuzz/fuzz_$target
  [ -x "$exe" ] || { echo "fuzz: no target '$target' ($exe)"; failed+=("$target"); continue; }
  corpus=$BUILD/corpus/$target
  mkdir -p "$corpus"
  cp fuzz/corpus/"$target"/* "$corpus/" 2>/dev/null || true
  seed "$target" "$corpus"
  log=$BUILD/logs/$target.log
  if "$exe" "$corpus" -seed="${FUZZ_SEED:-0}" -max_total_time="$SECONDS_PER_TARGET" -timeout=10 -rss_limit_mb=2048 \
       -artifact_prefix="$BUILD/crashes/$target-" -print_final_stats=1 >"$log" 2>&1; then
    echo "fuzz $target: $(grep -oE 'Done [0-9]+ runs in [0-9]+ second' "$log" | tail -n 1 | sed 's/ second/ s/'), no finding"
  else
    unit=$(ls -t "$BUILD"/crashes/"$target"-* 2>/dev/null | head -n 1)
    grep -E 'ERROR|SUMMARY|finding|deadly|Test unit written' "$log" | head -n 8 | sed 's/^/  /'
    # The input goes into the log too, so that a finding on a machine we cannot reach can be replayed.
    [ -z "$unit" ] || [ "$(stat -c %s "$unit")" -gt 16384 ] || { echo "  input (base64):"; base64 -w 120 "$unit" | sed 's/^/    /'; }
    # A timeout is replayed alone, once: one that does not recur was a stalled machine, not a slow input
    # (a slow input is slow again). It is said, and the input kept, but it fails nothing.
    replay_start=$SECONDS
    if [[ $unit == *-timeout-* ]] && timeout 120 "$exe" -timeout=10 -rss_limit_mb=2048 "$unit" >"$log.replay" 2>&1; then
      echo "fuzz $target: a unit timed out, but alone it ran in $((SECONDS - replay_start)) s: not a finding (input kept: $unit)"
    else
      echo "fuzz $target: FINDING (log $log, input $unit)"
      failed+=("$target")
    fi
  fi
done
if [ ${#failed[@]} -gt 0 ]; then
  echo "fuzz: findings in ${failed[*]}"
  exit 1
fi
echo "fuzz: ${#targets[@]} targets, ${SECONDS_PER_TARGET} s each, no finding"

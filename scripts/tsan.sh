#!/usr/bin/env bash
# ThreadSanitizer run where threads meet Clearway: builds the library, the OMPL plugin, its tests and the
# tool with -fsanitize=thread ($BUILD, default build-tsan) and runs the plugin's thread tests (four threads
# on shared checkers; pRRT with two threads; PRM growing its roadmap beside the solution search), a World
# edited while three threads query it (and the versioned tree under it), and `clearway plan` with pRRT and PRM. Any report fails the run (halt_on_error). OMPL itself is not
# instrumented: what TSan sees is Clearway's own memory.
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD=${BUILD:-build-tsan}
cmake -S . -B "$BUILD" -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG="-O1 -g1 -fsanitize=thread" \
  -DCMAKE_EXE_LINKER_FLAGS=-fsanitize=thread -DCMAKE_SHARED_LINKER_FLAGS=-fsanitize=thread \
  -DCLEARWAY_BUILD_TESTS=ON -DCLEARWAY_BUILD_BENCHMARKS=OFF -DCLEARWAY_BUILD_TOOLS=ON >/dev/null
cmake --build "$BUILD" -j2 --target clearway_tool test_ompl test_world test_tree
export TSAN_OPTIONS="halt_on_error=1 second_deadlock_stack=1"
"$BUILD/tests/test_ompl" --gtest_filter='*Thread*:*Parallel*'
"$BUILD/tests/test_world" --gtest_filter='*Thread*'
"$BUILD/tests/test_tree" --gtest_filter='VersionedAabbTree.ReadersOnOtherThreadsSeeTheirVersions'
for planner in pRRT PRM; do
  "$BUILD/clearway" plan --planner "$planner" --seed 4 --time 60 >/dev/null
  echo "tsan: clearway plan --planner $planner: no report"
done

#!/usr/bin/env bash
# ThreadSanitizer run where threads meet Clearway: builds the library, the OMPL plugin and the tests of
# both with -fsanitize=thread ($BUILD, default build-tsan) and runs the plugin's thread tests (four threads
# on shared checkers; pRRT with two threads; PRM growing its roadmap beside the solution search) and a
# World edited (obstacles, attached bodies: new versions of its trees) while three threads query it. Any
# report fails the run (halt_on_error). OMPL itself is not instrumented: what TSan sees is Clearway's own
# memory. (The tool's `plan` runs the same planners through the same plugin, single-threaded around them.)
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD=${BUILD:-build-tsan}
cmake -S . -B "$BUILD" -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG="-O1 -g1 -fsanitize=thread" \
  -DCMAKE_EXE_LINKER_FLAGS=-fsanitize=thread -DCMAKE_SHARED_LINKER_FLAGS=-fsanitize=thread \
  -DCLEARWAY_BUILD_TESTS=ON -DCLEARWAY_BUILD_BENCHMARKS=OFF -DCLEARWAY_BUILD_TOOLS=OFF -DCLEARWAY_BUILD_PYTHON=OFF >/dev/null
cmake --build "$BUILD" -j2 --target test_ompl test_world
export TSAN_OPTIONS="halt_on_error=1 second_deadlock_stack=1"
"$BUILD/tests/test_ompl" --gtest_filter='*Thread*:*Parallel*'
"$BUILD/tests/test_world" --gtest_filter='*Thread*'
echo "tsan: no report"

#!/usr/bin/env bash
# The test command: installs dependencies, builds with AddressSanitizer and UndefinedBehaviorSanitizer,
# and runs every test through CTest. The benchmark programs (benchmarks/, FCL side by side) are left to
# the Release build they are run from (benchmarks/build_bench.sh): compiling them sanitized, only not to
# run them, cost CI minutes of its 30. `clearway bench`'s suites are part of the tool and built here.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
BUILD=${BUILD:-build-test}
# -O1 with line tables only: the usual sanitizer setting, and it keeps CI's template-heavy build short.
cmake -S . -B "$BUILD" -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG="-O1 -g1" -DCLEARWAY_SANITIZE=ON \
  -DCLEARWAY_BUILD_TESTS=ON -DCLEARWAY_BUILD_BENCHMARKS=OFF -DCLEARWAY_BUILD_TOOLS=ON
cmake --build "$BUILD" -j2
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
ctest --test-dir "$BUILD" --output-on-failure -j2

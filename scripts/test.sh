#!/usr/bin/env bash
# The test command: installs dependencies, builds with AddressSanitizer and UndefinedBehaviorSanitizer,
# and runs every test through CTest, then lists the GoogleTest cases skipped. The benchmark programs
# (benchmarks/, FCL side by side) are left to the Release build they are run from (benchmarks/build_bench.sh):
# compiling them sanitized, only not to run them, cost CI minutes. `clearway bench`'s suites are part of
# the tool and built here.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
BUILD=${BUILD:-build-test}
# Clang: with UBSan's checks GCC 12 takes twice as long to compile (proximity.cpp 92 s against 39 s), and
# the tests run as fast. (A build folder keeps the compiler it was first configured with.)
# -O1 with line tables only: the usual sanitizer setting, and it keeps CI's template-heavy build short.
# About 32 GoogleTest cases per process (tests/CMakeLists.txt): sanitized, a robot's load costs more than
# most cases, and the cases of one process share it (ctest 1,180 s against 1,227 s with 16 a process).
CC=${CC:-clang} CXX=${CXX:-clang++} cmake -S . -B "$BUILD" -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG="-O1 -g1" \
  -DCLEARWAY_SANITIZE=ON -DCLEARWAY_BUILD_TESTS=ON -DCLEARWAY_BUILD_BENCHMARKS=OFF -DCLEARWAY_BUILD_TOOLS=ON \
  -DCLEARWAY_TEST_CASES_PER_PROCESS=32
cmake --build "$BUILD" -j2
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
ctest --test-dir "$BUILD" --output-on-failure -j2
# CTest then names processes, not cases: GoogleTest's log names the cases it skipped, and why.
log=$BUILD/Testing/Temporary/LastTest.log
cases=$({ grep -hE '^\[==========\] [0-9]+ tests? from .* ran' "$log" || true; } | awk '{n += $2} END {print n + 0}')
skipped=$({ grep -hE '^\[  SKIPPED \] [A-Za-z0-9_]+\.[A-Za-z0-9_]+ \(' "$log" || true; } |
  sed -E 's/^\[  SKIPPED \] ([^ ]+) .*/\1/' | sort -u)
echo "test.sh: $cases GoogleTest cases ran; skipped: $(printf '%s' "$skipped" | grep -c . || true)"
if [ -n "$skipped" ]; then
  printf '  %s\n' $skipped
  echo "  because:"; grep -hA1 ': Skipped$' "$log" | grep -vE ': Skipped$|^--$' | sort | uniq -c | sed 's/^/  /'
fi

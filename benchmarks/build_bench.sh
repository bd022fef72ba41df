# Sourced by the run_*.sh scripts: goes to the repository root and builds the given benchmark targets
# optimised (-O2) in their own build directory ($BUILD, default /tmp/build-bench), at low priority, with
# $JOBS jobs (default 2). Sets BUILD and OUT (default benchmarks/results, created).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
BUILD=${BUILD:-/tmp/build-bench}
OUT=${OUT:-benchmarks/results}
nice -n 10 cmake -S . -B "$BUILD" -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_FLAGS_RELEASE="-O2 -DNDEBUG" \
  -DCLEARWAY_BUILD_TESTS=OFF -DCLEARWAY_BUILD_TOOLS=ON -DCLEARWAY_BUILD_BENCHMARKS=ON >/dev/null
nice -n 10 cmake --build "$BUILD" -j"${JOBS:-2}" --target "$@"
mkdir -p "$OUT"

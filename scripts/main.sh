#!/usr/bin/env bash
# The main job: installs dependencies, builds Clearway (Release) and runs it on bundled input.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
BUILD=${BUILD:-build}
cmake -S . -B "$BUILD" -DCMAKE_BUILD_TYPE=Release -DCLEARWAY_BUILD_TESTS=OFF -DCLEARWAY_BUILD_BENCHMARKS=OFF
cmake --build "$BUILD" -j2 --target clearway_tool
"$BUILD/clearway" query robots/demo/queries.jsonl

#!/usr/bin/env bash
# The main job: installs dependencies, builds Clearway (Release) and plans a motion on the bundled
# robot and scene (robots/scenes/arm6_wall.yaml) with OMPL's RRTConnect and Clearway's certified checks.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
BUILD=${BUILD:-build}
cmake -S . -B "$BUILD" -DCMAKE_BUILD_TYPE=Release -DCLEARWAY_BUILD_TESTS=OFF -DCLEARWAY_BUILD_BENCHMARKS=OFF
cmake --build "$BUILD" -j2 --target clearway_tool
"$BUILD/clearway" plan robots/scenes/arm6_wall.yaml --seed 1 "$@"

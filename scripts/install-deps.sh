#!/usr/bin/env bash
# Installs every Debian package that Clearway's build, tests, tools and benchmarks need.
# Safe to run again; uses sudo when not root.
set -euo pipefail
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
packages=(
  build-essential cmake git pkg-config
  libeigen3-dev                      # geometry
  libhwy-dev                         # SIMD lanes (Highway, run-time dispatch)
  liburdfdom-dev libassimp-dev libtinyxml2-dev  # robots: URDF, meshes, SRDF
  liboctomap-dev                     # environment: OctoMap
  libompl-dev libboost-serialization-dev libboost-filesystem-dev libboost-system-dev  # OMPL plugin
  libyaml-cpp-dev nlohmann-json3-dev # scene files, query files
  libcli11-dev                       # the clearway tool's argument parser
  libgtest-dev libgmock-dev libbenchmark-dev  # tests and benchmarks
  python3-dev pybind11-dev python3-numpy python3-pytest  # the Python module and its tests
  python3-venv python3-setuptools python3-wheel  # pip install . (setup.py drives CMake; scripts/pip-check.sh)
  colcon python3-colcon-cmake python3-colcon-ros python3-colcon-recursive-crawl python3-colcon-parallel-executor
  python3-colcon-package-selection python3-colcon-bash python3-colcon-output  # a colcon workspace (scripts/colcon-check.sh)
  ccache                             # CI: one compiler cache for its three Release builds (.ci/run)
  doxygen                            # the API reference (target clearway_docs)
  libfcl-dev                         # benchmarks only: FCL side by side
  gnuplot-nox                        # benchmark plots (PNG)
  clang libfuzzer-14-dev             # scripts/test.sh (the sanitized build), scripts/fuzz.sh (libFuzzer, fuzz/)
  slurmd slurmctld slurm-client munge parallel  # clearway bench shards: the one-node Slurm test (GNU parallel without root)
)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ "${#missing[@]}" -gt 0 ]; then
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
echo "install-deps: all ${#packages[@]} packages present"

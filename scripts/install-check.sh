#!/usr/bin/env bash
# The install check (issue 21): what a user gets from the README's Install section, with the source gone.
# Copies this source tree (the files git knows) to a temporary folder, builds it there as the README
# says (Release; the library, the OMPL plugin and the tool), installs into a prefix, deletes the copy and
# its build, and moves the prefix to another path. Then, from a folder outside any source tree and with
# no CLEARWAY_SHARED or LD_LIBRARY_PATH: the installed tool's RUNPATH, `clearway --version`, `clearway
# plan` on its bundled scene, `clearway bench` without shared data (a clear message, exit 2), a
# downstream CMake project (find_package(clearway 0.1 REQUIRED COMPONENTS ompl), tests/install/downstream)
# and a pkg-config build of a one-line program, both run. Exit status 0 when every step passes, else 1
# naming the step. Usage: bash scripts/install-check.sh (JOBS=N for the build's -j, default 2).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
work=$(mktemp -d "${TMPDIR:-/tmp}/clearway-install-check.XXXXXX")
trap 'rm -rf "$work"' EXIT
step() { echo "install-check: $*" >&2; }
fail() { echo "install-check: FAILED: $*" >&2; exit 1; }

# The source in WORK/src/clearway and its build in WORK/build/clearway: laid out as colcon-check.sh's and
# pip-check.sh's Release builds, so that a compiler cache shared by them (.ci/run) serves all three.
step "copying the source to $work/src/clearway"
mkdir -p "$work/src/clearway"
# Tracked files (as modified in the working tree) and new files git does not ignore: a clone's content.
# A tracked file deleted in the working tree is skipped (--ignore-failed-read).
(cd "$root" && git ls-files -z --cached --others --exclude-standard | tar --null --ignore-failed-read -T - -cf - 2>/dev/null) |
  tar -xf - -C "$work/src/clearway"
version=$(sed -n 's/^project(clearway VERSION \([0-9.]*\).*/\1/p' "$work/src/clearway/CMakeLists.txt")
[ -n "$version" ] || fail "no version in CMakeLists.txt's project()"
cp -r "$work/src/clearway/tests/install/downstream" "$work/downstream"

step "building and installing (the README's Install section)"
(
  cd "$work/src/clearway"
  cmake -S . -B ../../build/clearway -DCMAKE_BUILD_TYPE=Release -DCLEARWAY_BUILD_TESTS=OFF -DCLEARWAY_BUILD_BENCHMARKS=OFF >/dev/null
  cmake --build ../../build/clearway -j"${JOBS:-2}" >/dev/null
  cmake --install ../../build/clearway --prefix "$work/prefix" >/dev/null
) || fail "the build or install"

# Nothing installed may need the source or the build tree, nor the path it was installed to.
rm -rf "$work/src" "$work/build"
mkdir "$work/moved" "$work/elsewhere"
mv "$work/prefix" "$work/moved/prefix"
P=$work/moved/prefix
cd "$work/elsewhere"
unset CLEARWAY_SHARED LD_LIBRARY_PATH

step "the installed tool"
readelf -d "$P/bin/clearway" | grep -q 'RUNPATH.*\$ORIGIN/\.\./lib' || fail "bin/clearway has no RUNPATH \$ORIGIN/../lib"
out=$("$P/bin/clearway" --version) || fail "clearway --version exited $?"
[ "$out" = "clearway $version" ] || fail "clearway --version printed '$out', expected 'clearway $version'"
"$P/bin/clearway" plan --seed 1 --time 10 >plan.out 2>plan.err || { cat plan.err >&2; fail "clearway plan (bundled scene) exited $?"; }
head -1 plan.out | grep -q '^path [0-9]' || fail "clearway plan printed no path: $(head -3 plan.out)"
grep -q "share/clearway/robots/scenes/arm6_wall.yaml" plan.err || fail "clearway plan did not plan on the installed scene: $(cat plan.err)"
status=0
"$P/bin/clearway" bench states --count 1 --out bench >/dev/null 2>bench.err || status=$?
[ "$status" = 2 ] || fail "clearway bench states without shared data exited $status, expected 2"
grep -q 'CLEARWAY_SHARED\|no benchmark suites' bench.err || fail "clearway bench without shared data said: $(cat bench.err)"

step "the installed CMake package and pkg-config file"
pc=$(find "$P" -name clearway.pc)
[ -n "$pc" ] || fail "no clearway.pc installed"
if grep -rlF "$work" "$P"/lib*/cmake "$(dirname "$pc")"; then fail "installed CMake or pkg-config files name the build's paths"; fi
if grep -l 'libompl\|ompl-1' "$P"/lib*/cmake/clearway/clearwayTargets*.cmake; then fail "the exported targets name OMPL's files instead of ompl::ompl"; fi
cmake -S "$work/downstream" -B "$work/downstream/build" -DCMAKE_PREFIX_PATH="$P" >"$work/downstream.log" 2>&1 &&
  cmake --build "$work/downstream/build" -j"${JOBS:-2}" >>"$work/downstream.log" 2>&1 ||
  { cat "$work/downstream.log" >&2; fail "the downstream project (find_package(clearway 0.1 REQUIRED COMPONENTS ompl))"; }
out=$("$work/downstream/build/downstream" "$P/share/clearway/robots/scenes/arm6_wall.yaml") || fail "downstream exited $?: $out"
[ "$out" = "start free" ] || fail "downstream printed '$out'"
cat >pc.cpp <<'CPP'
#include <clearway/narrowphase/gjk.h>
int main() { using namespace clearway; return gjkDistance(Shape(Sphere(1.0)), Pose(), Shape(Sphere(1.0)), Pose::translation(Vec3(3, 0, 0))).distance > 0.999 ? 0 : 1; }
CPP
flags=$(PKG_CONFIG_PATH="$(dirname "$pc")" pkg-config --cflags --libs clearway) || fail "pkg-config clearway"
# shellcheck disable=SC2086  # the flags are words
g++ -std=c++17 pc.cpp $flags -Wl,-rpath,"$(dirname "$(dirname "$pc")")" -o pc || fail "the pkg-config build ($flags)"
./pc || fail "the pkg-config program exited $?"
step "passed in ${SECONDS}s (clearway $version, prefix moved to $P)"

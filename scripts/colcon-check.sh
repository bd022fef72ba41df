#!/usr/bin/env bash
# The colcon route of the README (issue 42): a workspace holding the repository in src/ and a downstream
# package beside it (tests/install/downstream: <depend>clearway</depend>, find_package(clearway 0.1
# REQUIRED COMPONENTS ompl)). Copies the source (the files git knows, as install-check.sh does) to
# WS/src/clearway and the downstream package to WS/src/clearway_downstream, runs the README's colcon block
# verbatim in WS (scripts/readme-block.sh colcon), then checks that colcon built clearway before its user,
# that the downstream program runs against the workspace's clearway, and that the sourced workspace gives
# the tool and the Python module. Exit 0 when every step passes, else 1 naming the step.
# The build is the Release build install-check.sh and pip-check.sh make, laid out alike (WS/src/clearway,
# WS/build/clearway), so that a compiler cache shared by them (.ci/run) serves all three.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
ws=$(mktemp -d "${TMPDIR:-/tmp}/clearway-colcon-check.XXXXXX")
trap 'rm -rf "$ws"' EXIT
step() { echo "colcon-check: $*" >&2; }
fail() { echo "colcon-check: FAILED: $*" >&2; exit 1; }
command -v colcon >/dev/null || fail "colcon is not installed (Debian: colcon python3-colcon-cmake python3-colcon-ros ...; scripts/install-deps.sh)"

step "a workspace in $ws: src/clearway (the source) and src/clearway_downstream"
mkdir -p "$ws/src/clearway"
(cd "$root" && git ls-files -z --cached --others --exclude-standard | tar --null --ignore-failed-read -T - -cf - 2>/dev/null) |
  tar -xf - -C "$ws/src/clearway"
cp -r "$root/tests/install/downstream" "$ws/src/clearway_downstream"
block=$(bash "$root/scripts/readme-block.sh" colcon)

step "the README's colcon block, in the workspace"
printf '%s\n' "$block" | sed 's/^/  | /' >&2
# (No -u: colcon's setup.sh reads unset variables, as interactive shells allow.)
(cd "$ws" && bash -e -o pipefail -c "$block") >"$ws/route.log" 2>&1 || { tail -40 "$ws/route.log" >&2; fail "the README's colcon block"; }
grep -q '^path [0-9]' "$ws/route.log" || fail "the block's clearway plan printed no path: $(tail -5 "$ws/route.log")"

step "the downstream package found clearway in the workspace"
order=$(grep -o 'Finished <<< [a-z_]*' "$ws/route.log" | awk '{print $3}' | tr '\n' ' ')
[ "$order" = "clearway clearway_downstream " ] || fail "colcon finished '$order', expected clearway before clearway_downstream"
grep -q "clearway_DIR:PATH=$ws/install/clearway/" "$ws/build/clearway_downstream/CMakeCache.txt" ||
  fail "the downstream package found another clearway: $(grep clearway_DIR "$ws/build/clearway_downstream/CMakeCache.txt")"
out=$(cd / && "$ws/build/clearway_downstream/downstream" "$ws/install/clearway/share/clearway/robots/scenes/arm6_wall.yaml") ||
  fail "the downstream program exited $?: $out"
[ "$out" = "start free" ] || fail "the downstream program printed '$out'"

step "the sourced workspace: the tool and the Python module are the workspace's"
# shellcheck disable=SC1091  # made by colcon
found=$(cd / && set +u && . "$ws/install/setup.sh" && command -v clearway && /usr/bin/python3 -c 'import clearway; print(clearway.__file__)') ||
  fail "sourcing install/setup.sh"
for f in $found; do
  case "$f" in "$ws/install/clearway/"*) ;; *) fail "not from the workspace: $f" ;; esac
done
step "passed in ${SECONDS}s"

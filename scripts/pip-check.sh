#!/usr/bin/env bash
# The pip route of the README (issue 42): copies the source (the files git knows) to WORK/src/clearway and
# runs the README's pip block verbatim there (scripts/readme-block.sh pip: a venv that sees Debian's
# setuptools, wheel and numpy, `pip install --no-build-isolation .`, a plan). Then, with the source and
# its build deleted and from another folder: the venv's python imports clearway from the venv, loads
# libclearway and libclearway_ompl from clearway.libs/ beside it, finds the stubs there and plans a
# certified path on the bundled scene; the README's pip-uninstall block then leaves the venv file for file
# as a fresh one. Exit 0 when every step passes, else 1 naming the step.
# HOME is a folder of the check (the README's ~), and /usr/bin comes first on PATH: the README means
# Debian's python3, which a developer's pyenv may shadow. CMake builds in WORK/build/clearway
# (CLEARWAY_BUILD_DIR), laid out as install-check.sh's and colcon-check.sh's builds for a shared compiler
# cache (.ci/run).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
work=$(mktemp -d "${TMPDIR:-/tmp}/clearway-pip-check.XXXXXX")
trap 'rm -rf "$work"' EXIT
step() { echo "pip-check: $*" >&2; }
fail() { echo "pip-check: FAILED: $*" >&2; exit 1; }
export HOME=$work/home PATH=/usr/bin:$PATH CLEARWAY_BUILD_DIR=$work/build/clearway
export CMAKE_BUILD_PARALLEL_LEVEL=${JOBS:-2}
mkdir -p "$HOME" "$work/src/clearway" "$work/elsewhere"
(cd "$root" && git ls-files -z --cached --others --exclude-standard | tar --null --ignore-failed-read -T - -cf - 2>/dev/null) |
  tar -xf - -C "$work/src/clearway"
install_block=$(bash "$root/scripts/readme-block.sh" pip)
uninstall_block=$(bash "$root/scripts/readme-block.sh" pip-uninstall)
venv=$(printf '%s\n' "$install_block" | sed -n 's/^python3 -m venv --system-site-packages \([^ ]*\).*/\1/p' | head -1)
[ -n "$venv" ] || fail "the README's pip block makes no venv with 'python3 -m venv --system-site-packages DIR'"
venv=${venv/#\~/$HOME}

step "the README's pip block, in the source folder"
printf '%s\n' "$install_block" | sed 's/^/  | /' >&2
start=$SECONDS
(cd "$work/src/clearway" && bash -e -o pipefail -c "$install_block") >"$work/route.log" 2>&1 ||
  { tail -40 "$work/route.log" >&2; fail "the README's pip block"; }
step "installed and planned in $((SECONDS - start)) s"
grep -q '^<PlanResult solved: ' "$work/route.log" || fail "the block's plan: $(tail -3 "$work/route.log")"

step "the installed module, with the source and its build gone, from another folder"
cp -r "$work/src/clearway/robots" "$work/robots"
rm -rf "$work/src" "$work/build"
site=$("$venv/bin/python" -c 'import sysconfig; print(sysconfig.get_paths()["platlib"])')
(cd "$work/elsewhere" && "$venv/bin/python" - "$site" "$work/robots/scenes/arm6_wall.yaml") <<'PY' || fail "the installed module"
import os, sys
import clearway
site, scene_file = sys.argv[1], sys.argv[2]
assert os.path.dirname(clearway.__file__) == site, (clearway.__file__, site)
libs = {line.split()[-1] for line in open("/proc/self/maps") if "libclearway" in line}
assert libs == {f"{site}/clearway.libs/libclearway.so.0", f"{site}/clearway.libs/libclearway_ompl.so.0"}, libs
assert os.path.exists(os.path.join(site, "clearway.pyi")), "no stubs beside the module"
scene = clearway.Scene.load(scene_file)
r = clearway.plan(scene, seed=1, time=30)
assert r.solved, r
free, _ = scene.check_motions(r.path[:-1], r.path[1:])
assert free.all(), r
print("pip-check: planned", r)
PY

step "the README's pip-uninstall block leaves the venv as a fresh one"
(cd "$work/elsewhere" && bash -e -o pipefail -c "$uninstall_block") >"$work/uninstall.log" 2>&1 ||
  { cat "$work/uninstall.log" >&2; fail "the README's pip-uninstall block"; }
python3 -m venv --system-site-packages "$work/fresh"
list() { (cd "$1" && find . -not -name '*.pyc' -not -name __pycache__ | sort); }
if ! diff <(list "$venv") <(list "$work/fresh") >"$work/left.diff"; then
  cat "$work/left.diff" >&2
  fail "pip uninstall left files behind (or removed some)"
fi
step "passed in ${SECONDS}s"

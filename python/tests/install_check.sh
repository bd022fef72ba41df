#!/bin/sh
# The README's promise about installing: after `cmake --install BUILD --prefix PREFIX`, python3 imports
# clearway from PREFIX/PYDIR (and the module finds libclearway beside it, not in the build tree), with its
# type stubs beside it.
#   install_check.sh CMAKE BUILD PREFIX PYDIR PYTHON
set -eu
cmake=$1 build=$2 prefix=$3 pydir=$4 python=$5
rm -rf "$prefix"
"$cmake" --install "$build" --prefix "$prefix" >/dev/null
cd "$prefix"
PYTHONPATH="$prefix/$pydir" "$python" -c '
import sys, clearway
assert clearway.__file__.startswith(sys.argv[1] + "/"), clearway.__file__
libs = {line.split()[-1] for line in open("/proc/self/maps") if "libclearway" in line}
assert libs and all(lib.startswith(sys.argv[1] + "/") for lib in libs), libs
import os
assert os.path.exists(os.path.join(os.path.dirname(clearway.__file__), "clearway.pyi")), "no stubs beside the module"
print("imported", clearway.__file__)' "$prefix"

#!/usr/bin/env bash
# The API reference builds with no warning (issue 42): configures a build folder ($BUILD, default
# build-docs; nothing is compiled) and builds the target clearway_docs, which runs Doxygen over the
# installed headers of the library and the OMPL plugin (docs/Doxyfile.in). Any warning fails it: a public
# declaration without its `///` promise, or a comment Doxygen cannot read. HTML in $BUILD/docs/html.
set -euo pipefail
cd "$(dirname "$0")/.."
command -v doxygen >/dev/null || { echo "docs-check: doxygen not found (bash scripts/install-deps.sh)" >&2; exit 1; }
BUILD=${BUILD:-build-docs}
cmake -S . -B "$BUILD" -DCMAKE_BUILD_TYPE=Release -DCLEARWAY_BUILD_DOCS=ON -DCLEARWAY_BUILD_TESTS=OFF \
  -DCLEARWAY_BUILD_BENCHMARKS=OFF -DCLEARWAY_BUILD_TOOLS=OFF -DCLEARWAY_BUILD_PYTHON=OFF >/dev/null
cmake --build "$BUILD" --target clearway_docs
echo "docs-check: the API reference built with no warning ($BUILD/docs/html/index.html)"

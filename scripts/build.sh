#!/usr/bin/env bash
# Configures and builds Atlas (Release, Ninja, ccache) into ${ATLAS_BUILD_DIR:-build}.
#   scripts/build.sh                  everything: library, atlas, tests, benchmarks, Python module
#   scripts/build.sh --program-only   just the atlas program and what it links (scripts/demo.sh)
# Other arguments go to CMake, e.g. scripts/build.sh -DATLAS_SANITIZE=ON.
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR="${ATLAS_BUILD_DIR:-build}"
JOBS="${ATLAS_BUILD_JOBS:-$(nproc)}"
export CCACHE_DIR="${CCACHE_DIR:-$HOME/.cache/ccache}"
# Paths relative to the checkout, so a fresh clone elsewhere still hits the cache.
export CCACHE_BASEDIR="${CCACHE_BASEDIR:-$(pwd)}"
export CCACHE_NOHASHDIR=1
target=()
parts=ON
if [ "${1:-}" = "--program-only" ]; then
  shift
  target=(--target atlas)
  parts=OFF
fi
# A build folder configured for the other kind of build is reconfigured (the cache keeps the objects).
configured=""
[ -f "$BUILD_DIR/CMakeCache.txt" ] && configured="$(sed -n 's/^ATLAS_BUILD_TESTS:BOOL=//p' "$BUILD_DIR/CMakeCache.txt")"
if [ ! -f "$BUILD_DIR/build.ninja" ] || [ $# -gt 0 ] || [ "$configured" != "$parts" ]; then
  cmake -S . -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE="${ATLAS_BUILD_TYPE:-Release}" \
        -DATLAS_BUILD_TESTS=$parts -DATLAS_BUILD_BENCHMARKS=$parts -DATLAS_BUILD_PYTHON=$parts "$@" >&2
fi
cmake --build "$BUILD_DIR" -j "$JOBS" "${target[@]}" >&2

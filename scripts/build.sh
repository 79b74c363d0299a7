#!/usr/bin/env bash
# Configures and builds Atlas (Release, Ninja, ccache) into ${ATLAS_BUILD_DIR:-build}.
# Extra arguments go to CMake, e.g. scripts/build.sh -DATLAS_SANITIZE=ON.
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR="${ATLAS_BUILD_DIR:-build}"
JOBS="${ATLAS_BUILD_JOBS:-$(nproc)}"
export CCACHE_DIR="${CCACHE_DIR:-$HOME/.cache/ccache}"
# Paths relative to the checkout, so a fresh clone elsewhere still hits the cache.
export CCACHE_BASEDIR="${CCACHE_BASEDIR:-$(pwd)}"
export CCACHE_NOHASHDIR=1
if [ ! -f "$BUILD_DIR/build.ninja" ] || [ $# -gt 0 ]; then
  cmake -S . -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE="${ATLAS_BUILD_TYPE:-Release}" "$@" >&2
fi
cmake --build "$BUILD_DIR" -j "$JOBS" >&2

#!/usr/bin/env bash
# Installs what is missing, builds, and runs the whole test suite (ctest).
# Usage: scripts/test.sh [ctest arguments], e.g. scripts/test.sh -R graph
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
bash scripts/build.sh
BUILD_DIR="${ATLAS_BUILD_DIR:-build}"
cd "$BUILD_DIR"
ctest --output-on-failure -j "$(nproc)" --timeout 600 "$@"

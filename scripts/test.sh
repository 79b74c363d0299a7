#!/usr/bin/env bash
# Installs what is missing, builds, and runs the whole test suite (ctest).
# First the numerical suites (core, noise, compress, sim) are built with
# AddressSanitizer and UndefinedBehaviorSanitizer and run (other suites:
# ATLAS_SANITIZE_SUITES; skip:
# ATLAS_SKIP_SANITIZERS=1); then the Release build runs everything, so ctest's
# summary is the last word.
# Usage: scripts/test.sh [ctest arguments], e.g. scripts/test.sh -R graph
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh

# Suites built and run under ASan + UBSan first. CI runs the suites of the
# modules that link nothing but core and TBB (about 4 min cold on 2 cores);
# set ATLAS_SANITIZE_SUITES="... graph_test io_test ..." for more (those pull in
# OpenVDB/OpenImageIO/CGAL, so a full list roughly doubles a cold build).
SANITIZE_SUITES="${ATLAS_SANITIZE_SUITES:-core_test noise_test compress_test sim_test}"
if [ "${ATLAS_SKIP_SANITIZERS:-0}" != "1" ] && [ $# -eq 0 ] && [ -n "$SANITIZE_SUITES" ]; then
  echo "== sanitizer run (ASan + UBSan): $SANITIZE_SUITES" >&2
  SAN_DIR="${ATLAS_SANITIZER_BUILD_DIR:-build-asan}"
  export CCACHE_BASEDIR="${CCACHE_BASEDIR:-$(pwd)}" CCACHE_NOHASHDIR=1
  cmake -S . -B "$SAN_DIR" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DATLAS_SANITIZE=ON \
        -DATLAS_BUILD_BENCHMARKS=OFF >/dev/null
  # shellcheck disable=SC2086
  cmake --build "$SAN_DIR" -j "$(nproc)" --target $SANITIZE_SUITES >&2
  for suite in $SANITIZE_SUITES; do
    ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
      "$SAN_DIR/tests/$suite" --gtest_brief=1 >&2
  done
  echo "== sanitizer run passed" >&2
fi

echo "== Release build and full test suite" >&2
bash scripts/build.sh
BUILD_DIR="${ATLAS_BUILD_DIR:-build}"
cd "$BUILD_DIR"
ctest --output-on-failure -j "$(nproc)" --timeout 900 "$@"

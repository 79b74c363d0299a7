#!/usr/bin/env bash
# Installs what is missing, builds, and runs the whole test suite (ctest).
# First the numerical suites (core, noise, compress, sim) are built with
# AddressSanitizer and UndefinedBehaviorSanitizer and run (CI's budget: every
# suite under sanitizers costs a second full compile, ~19 min on a machine with
# no ccache; ATLAS_SANITIZE_SUITES=all runs every GoogleTest suite with ctest -L
# unit, or name suites: ATLAS_SANITIZE_SUITES="core_test io_test"; skip:
# ATLAS_SKIP_SANITIZERS=1); then the Release build runs everything, so ctest's
# summary is the last word.
# Usage: scripts/test.sh [ctest arguments], e.g. scripts/test.sh -R graph
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh

# The sanitizer build: -O2 with line tables only (-g1: file:line in reports at a
# fraction of -g's compile time and object size), no benchmarks, no Python module.
if [ "${ATLAS_SKIP_SANITIZERS:-0}" != "1" ] && [ $# -eq 0 ]; then
  SAN_DIR="${ATLAS_SANITIZER_BUILD_DIR:-build-asan}"
  export CCACHE_DIR="${CCACHE_DIR:-$HOME/.cache/ccache}"
  export CCACHE_BASEDIR="${CCACHE_BASEDIR:-$(pwd)}" CCACHE_NOHASHDIR=1
  cmake -S . -B "$SAN_DIR" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DATLAS_SANITIZE=ON \
        -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG" -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG" \
        -DATLAS_BUILD_BENCHMARKS=OFF -DATLAS_BUILD_PYTHON=OFF >/dev/null
  export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1
  export LSAN_OPTIONS="suppressions=$(pwd)/tests/sanitizer/lsan.supp:print_suppressions=0"
  export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
  SANITIZE_SUITES="${ATLAS_SANITIZE_SUITES:-core_test noise_test compress_test sim_test}"
  if [ "$SANITIZE_SUITES" != "all" ]; then
    echo "== sanitizer run (ASan + UBSan): $SANITIZE_SUITES" >&2
    # shellcheck disable=SC2086
    cmake --build "$SAN_DIR" -j "$(nproc)" --target $SANITIZE_SUITES >&2
    for suite in $SANITIZE_SUITES; do "$SAN_DIR/tests/$suite" --gtest_brief=1 >&2; done
  else
    echo "== sanitizer run (ASan + UBSan): every GoogleTest suite" >&2
    cmake --build "$SAN_DIR" -j "$(nproc)" --target unit_suites >&2
    (cd "$SAN_DIR" && ctest -L unit -j "$(nproc)" --timeout 900 --output-on-failure >&2)
  fi
  echo "== sanitizer run passed" >&2
fi

echo "== Release build and full test suite" >&2
bash scripts/build.sh
BUILD_DIR="${ATLAS_BUILD_DIR:-build}"
cd "$BUILD_DIR"
ctest --output-on-failure -j "$(nproc)" --timeout 900 "$@"

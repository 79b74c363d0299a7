#!/usr/bin/env bash
# Installs what is missing, builds, and runs the whole test suite (ctest), the way
# CI runs it: ONE build, clang 14 at -O2 with AddressSanitizer and
# UndefinedBehaviorSanitizer, and every test in it (GoogleTest suites, CLI and
# graph cooks, fuzz smoke runs, Python, Blender, benchmark smoke runs). One
# instrumented build costs what the Release build costs (~17 min cold on 2 cores)
# where a second build for the sanitizers did not fit CI's budget
# (docs/DECISIONS.md, 2026-12-03).
#
#   ATLAS_TEST_BUILD=release   the GCC Release build instead (scripts/build.sh, what
#                              demo.sh and users build): every test, no sanitizers
#   scripts/test.sh [ctest arguments], e.g. scripts/test.sh -R graph
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
bash scripts/web.sh

if [ "${ATLAS_TEST_BUILD:-sanitized}" = "release" ]; then
  echo "== Release build (GCC) and the whole test suite" >&2
  bash scripts/build.sh
  cd "${ATLAS_BUILD_DIR:-build}"
  exec ctest --output-on-failure -j "$(nproc)" --timeout 900 "$@"
fi

# -O2 with line tables only (-g1: file:line in reports at a fraction of -g's cost).
BUILD_DIR="${ATLAS_SANITIZER_BUILD_DIR:-build-asan}"
JOBS="${ATLAS_BUILD_JOBS:-$(nproc)}"
export CCACHE_DIR="${CCACHE_DIR:-$HOME/.cache/ccache}"
export CCACHE_BASEDIR="${CCACHE_BASEDIR:-$(pwd)}" CCACHE_NOHASHDIR=1
if [ ! -f "$BUILD_DIR/build.ninja" ]; then
  CC=clang-14 CXX=clang++-14 cmake -S . -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DATLAS_SANITIZE=ON \
        -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG" -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG" >&2
fi
echo "== build (clang, ASan + UBSan) and the whole test suite" >&2
cmake --build "$BUILD_DIR" -j "$JOBS" >&2
# Leaks are errors, UB stops the program; tests that load Atlas into another program
# (Python, Blender) get the ASan runtime preloaded (tests/CMakeLists.txt).
export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1}"
export LSAN_OPTIONS="suppressions=$(pwd)/tests/sanitizer/lsan.supp:print_suppressions=0"
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
cd "$BUILD_DIR"
exec ctest --output-on-failure -j "$(nproc)" --timeout 900 "$@"

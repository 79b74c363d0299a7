#!/usr/bin/env bash
# Atlas's noise kernels against FastNoise2 in the same run (issue 49 item 1; not in CI).
#
#   bench/compare_fastnoise2.sh FASTNOISE2_SRC FASTSIMD_SRC [BUILD_DIR] [ROUNDS]
#
# FASTNOISE2_SRC and FASTSIMD_SRC are checkouts made outside the repository
# (github.com/Auburn/FastNoise2 and the FastSIMD commit its src/CMakeLists.txt
# pins); nothing is downloaded. FastNoise2 is configured and built in a temp
# folder (Release, its CPM pointed at FASTSIMD_SRC), bench/noise_peer_fn2.cpp
# is compiled against it, and then, ROUNDS times (default 2), Atlas's
# noise_bench (BM_Peer3D_Atlas at 128^3: Perlin and Worley F1 on each SIMD path
# the CPU has, one thread) and the FastNoise2 program run one after the other.
# Run it on an idle machine.
set -euo pipefail
FN2=$(realpath "${1:?FastNoise2 source folder}")
FSIMD=$(realpath "${2:?FastSIMD source folder}")
BUILD=$(realpath "${3:-build}")
ROUNDS=${4:-2}
ROOT=$(cd "$(dirname "$0")/.." && pwd)
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
cmake -S "$FN2" -B "$WORK/fn2" -G Ninja -DCMAKE_BUILD_TYPE=Release -DFASTNOISE2_TOOLS=OFF \
  -DCPM_FastSIMD_SOURCE="$FSIMD" >"$WORK/configure.log" 2>&1 || { cat "$WORK/configure.log"; exit 1; }
ninja -C "$WORK/fn2" >"$WORK/build.log" 2>&1 || { tail -30 "$WORK/build.log"; exit 1; }
LIB=$(find "$WORK/fn2" -name libFastNoise.a | head -1)
g++ -O3 -std=c++17 "$ROOT/bench/noise_peer_fn2.cpp" -I"$FN2/include" -I"$FSIMD/include" -DFASTNOISE_STATIC_LIB "$LIB" -o "$WORK/fn2bench"
echo "FastNoise2 $(git -C "$FN2" log -1 --format=%h 2>/dev/null || echo '?'), load before: $(cut -d' ' -f1-3 /proc/loadavg)"
for r in $(seq 1 "$ROUNDS"); do
  echo "round $r"
  "$BUILD/bench/noise_bench" --benchmark_filter='BM_Peer3D_Atlas/./128/' --benchmark_repetitions=3 \
    --benchmark_report_aggregates_only=true 2>/dev/null | grep median | sed -E 's/.*items_per_second=([0-9.]+M\/s) atlas (\w+), (\w+)/Atlas      \3 \2 \1/'
  "$WORK/fn2bench"
done
echo "load after: $(cut -d' ' -f1-3 /proc/loadavg)"

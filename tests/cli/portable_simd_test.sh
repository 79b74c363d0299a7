#!/usr/bin/env bash
# Issue 46 item 4: a tiled world cooked on the portable paths (ATLAS_SIMD=scalar: noise kernels and
# BC1/BC4 encoders without AVX2) is byte-identical to the one cooked on this CPU's fastest paths,
# every output and tile file compared. Exit 77 (skipped) on a CPU without AVX2: the two cooks would
# run the same code.
#   portable_simd_test.sh ATLAS SOURCE_DIR WORK_DIR
set -euo pipefail
atlas="$1" src="$2" work="$3"
grep -qw avx2 /proc/cpuinfo || { echo "no AVX2 on this CPU: nothing to compare"; exit 77; }
rm -rf "$work" && mkdir -p "$work"
cook() {
  ATLAS_CACHE_DIR= "$@" "$atlas" cook "$src/tests/graph/tiling/world.yaml" --tiles 2,2 --assemble --no-cache --quiet --out "$work/$name" >/dev/null
}
name=fast cook env
name=portable cook env ATLAS_SIMD=scalar
n=$(find "$work/fast" -type f | wc -l)
test "$n" -gt 10 || { echo "FAIL: only $n files written"; exit 1; }
ls "$work/fast/maps" | grep -q '_bc4.dds' || { echo "FAIL: no BC4 output to compare"; exit 1; }
# The records name their run (paths, times); every other file must be the same bytes.
if ! diff -r -x '.atlas-outputs.json' -x '*.json' "$work/fast" "$work/portable"; then
  echo "FAIL: the portable paths wrote different bytes"; exit 1
fi
echo "ok: $n files, the same bytes on the AVX2 and the portable paths"

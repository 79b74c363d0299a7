#!/usr/bin/env bash
# Issue 46 item 2: a shipped graph, at a reduced size, cooked in tiles (1x1, 2x2 and 3x2 or, with
# TILES="...", the splits named there; assembled) writes every output byte for byte as its untiled
# cook does, including those written whole (on a grid of their own).
# A second identical tiled cook then writes nothing.
#   [TILES="1,1 2,2 4,2"] [MIN_FILES=3] shipped_tiles_test.sh ATLAS SOURCE_DIR WORK_DIR GRAPH [--set NODE.PARAM=VALUE ...]
set -euo pipefail
atlas="$1" src="$2" work="$3" graph="$4"
shift 4
rm -rf "$work" && mkdir -p "$work"
cook() { # cook NAME [ARGS...]
  local name="$1"
  shift
  ATLAS_CACHE_DIR= "$atlas" cook "$src/$graph" "$@" --no-cache --quiet --out "$work/$name" >/dev/null
}
cook untiled "$@"
n=$(find "$work/untiled" -type f ! -name '.atlas-outputs.json' | wc -l)
test "$n" -ge "${MIN_FILES:-3}" || { echo "FAIL: the untiled cook wrote only $n files"; exit 1; }
for tiles in ${TILES:-1,1 2,2 3,2}; do
  cook "tiled_$tiles" "$@" --tiles "$tiles" --assemble
  test -f "$work/tiled_$tiles/tiles/index.json" || { echo "FAIL: --tiles $tiles wrote no tile index"; exit 1; }
  # Everything the untiled cook wrote but its record of the run (paths, times).
  if ! diff -r -x '.atlas-outputs.json' -x tiles "$work/untiled" "$work/tiled_$tiles"; then
    echo "FAIL: --tiles $tiles assembled different bytes from the untiled cook"; exit 1
  fi
  tile_files=$(find "$work/tiled_$tiles/tiles" -type f | wc -l)
  echo "ok: --tiles $tiles, $n files the same bytes, $tile_files tile files"
done
# Issue 46 item 5: the same tiled cook again (assembly included) is a no-op: nothing is cooked,
# encoded or written, no file's mtime moves; an untiled cook into that folder finds it current too.
last="$work/tiled_$tiles"
before=$(find "$last" -type f -printf '%T@ %p\n' | sort)
again=$(ATLAS_CACHE_DIR= "$atlas" cook "$src/$graph" "$@" --tiles "$tiles" --assemble --no-cache --quiet --out "$last")
case "$again" in *"cooked 0 of "*"wrote 0 files"*) ;; *) echo "FAIL: a second identical tiled cook was not a no-op: $again"; exit 1 ;; esac
test "$before" = "$(find "$last" -type f -printf '%T@ %p\n' | sort)" || { echo "FAIL: the second tiled cook touched files"; exit 1; }
untiled=$(ATLAS_CACHE_DIR= "$atlas" cook "$src/$graph" "$@" --no-cache --quiet --out "$last")
case "$untiled" in *"wrote 0 files"*) ;; *) echo "FAIL: an untiled cook rewrote the assembled outputs: $untiled"; exit 1 ;; esac
echo "ok: a second identical tiled cook and an untiled one wrote nothing"


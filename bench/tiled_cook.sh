#!/usr/bin/env bash
# Out-of-core tiled cook (issue 19, docs/scale.md): every tile of a graph in its
# own process (as a cluster worker runs it), each with wall, CPU and peak RSS,
# then the totals and the untiled cook refused under the same memory budget.
# Not a test: it prints the figures and the load average.
# Usage: bench/tiled_cook.sh [BUILD_DIR] [GRAPH] [NX,NY] [BUDGET]
set -euo pipefail
BUILD="${1:-build}"
GRAPH="${2:-bench/tiled_world.yaml}"
TILES="${3:-4,4}"
BUDGET="${4:-512MiB}"
WORK="$(mktemp -d /tmp/atlas_tiled_XXXXXX)"
trap 'rm -rf "$WORK"' EXIT
NX="${TILES%,*}"; NY="${TILES#*,}"
echo "graph $GRAPH, tiles $TILES, budget $BUDGET, load $(cut -d' ' -f1-3 /proc/loadavg)"
tw=0; tc=0; peak=0
for ((j = 0; j < NY; j++)); do
  for ((i = 0; i < NX; i++)); do
    /usr/bin/time -f "%e %U %S %M" -o "$WORK/time" "$BUILD/bin/atlas" cook "$GRAPH" --tiles "$TILES" --tile "$i,$j" \
      --out "$WORK/out" --memory-budget "$BUDGET" --jobs 2 --quiet >/dev/null
    read -r wall user sys rss <"$WORK/time"
    cpu="$(echo "$user + $sys" | bc)"
    echo "tile $i,$j: wall $wall s, cpu $cpu s, peak RSS $((rss / 1024)) MiB, load $(cut -d' ' -f1 /proc/loadavg)"
    tw="$(echo "$tw + $wall" | bc)"; tc="$(echo "$tc + $cpu" | bc)"
    [ "$rss" -gt "$peak" ] && peak="$rss"
  done
done
/usr/bin/time -f "%e %U %S %M" -o "$WORK/time" "$BUILD/bin/atlas" cook "$GRAPH" --tiles "$TILES" --out "$WORK/out" --quiet >/dev/null
read -r iwall iuser isys irss <"$WORK/time"
echo "total over $((NX * NY)) tiles: wall $tw s, cpu $tc s, largest peak RSS $((peak / 1024)) MiB"
echo "index (every tile current, nothing cooked): wall $iwall s, peak RSS $((irss / 1024)) MiB"
echo "tile files: $(du -sh "$WORK/out/tiles" | cut -f1)"
if "$BUILD/bin/atlas" cook "$GRAPH" --out "$WORK/untiled" --memory-budget "$BUDGET" --quiet >/dev/null 2>"$WORK/err"; then
  echo "untiled cook under $BUDGET: succeeded"
else
  echo "untiled cook under $BUDGET: refused: $(tail -1 "$WORK/err")"
fi

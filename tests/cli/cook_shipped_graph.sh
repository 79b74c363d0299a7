#!/usr/bin/env bash
# Every shipped graph cooks on a fresh clone (issue 45 item 4): cooks GRAPH (relative to the
# source tree) in a scratch copy of graphs/ and examples/, so nothing is written into the tree
# and no output of an earlier cook is there to be read.
#   cook_shipped_graph.sh ATLAS SOURCE_DIR WORK_DIR GRAPH
# The solver graphs cook at their documented quick size (32^3, 125 m cells): the tower of
# cumulus_growth.yaml (read by cumulus_cloudscape and cumulus_side_view through their requires:,
# grown first here so that `atlas cook` finds it) takes minutes at 128^3, periodic_cumulus_field
# a minute and a half under the sanitizers at 64^3.
set -euo pipefail
atlas="$1" src="$2" work="$3" graph="$4"
rm -rf "$work" && mkdir -p "$work"
cp -r "$src/graphs" "$src/examples" "$work/"
rm -rf "$work/graphs/cumulus_out"
cd "$work"
quick=(--set cloud.resolution=[32,32,32] --set cloud.dx=125)
case "$graph" in
  graphs/cumulus_growth.yaml|graphs/periodic_cumulus_field.yaml|graphs/cumulus_sequence.yaml)   # solver graphs: their quick size
    exec "$atlas" cook "$graph" --out out --no-cache --quiet "${quick[@]}" ;;
  graphs/cumulus_cloudscape.yaml|graphs/cumulus_side_view.yaml)
    "$atlas" cook graphs/cumulus_growth.yaml --out graphs/cumulus_out --no-cache --quiet "${quick[@]}" >/dev/null ;;
esac
"$atlas" cook "$graph" --out out --no-cache --quiet
test -n "$(ls -A out)" || { echo "FAIL: $graph wrote nothing"; exit 1; }

#!/usr/bin/env bash
# Renders each shipped voxel graph's cloud beside Guerrilla's two production clouds
# (the Nubis voxel pack) with the same camera preset and the same light, for a person
# to judge (docs/look.md). Fetches nothing and writes nothing into the repository:
# the pack's folder is an argument (the TGA slice stacks, e.g. a copy of
# src/images/vdb from the public Frostnova repository), the pictures go to OUT.
#
#   scripts/look_vs_pack.sh PACK_DIR OUT [ATLAS_BIN]
#
# PACK_DIR holds example1/tga/modeling_data(0).tga + field_data.001.tga ... and
# example2/tga/modeling_data(0).tga + field_data(0).tga .... Every cloud is drawn as
# files (atlas preview FILE, so one look for all), from the ground and in orbit;
# OUT/compare_VIEW.png puts them side by side (ours first, then the pack's two).
set -euo pipefail
[ $# -ge 2 ] || { echo "usage: $0 PACK_DIR OUT [ATLAS_BIN]" >&2; exit 2; }
PACK="$1"
OUT="$2"
ATLAS="${3:-build/bin/atlas}"
cd "$(dirname "$0")/.."
mkdir -p "$OUT"
WORK="$(mktemp -d)"
trap 'rm -rf "$WORK"' EXIT
for f in "$PACK/example1/tga/modeling_data(0).tga" "$PACK/example1/tga/field_data.001.tga" \
         "$PACK/example2/tga/modeling_data(0).tga" "$PACK/example2/tga/field_data(0).tga"; do
  [ -f "$f" ] || { echo "$0: $f is missing (PACK_DIR must hold example1/tga and example2/tga)" >&2; exit 1; }
done
SIZE=640x360
# Ours: each graph's NVDF set as a VDB file (the graph's own cook, nothing else).
"$ATLAS" cook graphs/towering_cumulus.yaml --out "$WORK/tc" --output towering_cumulus.vdb --quiet >/dev/null
"$ATLAS" cook graphs/cloudscape.yaml --out "$WORK/cs" --output nvdf/cloudscape.vdb --quiet >/dev/null
"$ATLAS" cook examples/quickstart.yaml --out "$WORK/qs" --output nvdf.vdb --quiet >/dev/null
for view in ground orbit; do
  pics=()
  for name in tc/towering_cumulus.vdb cs/nvdf/cloudscape.vdb qs/nvdf.vdb; do
    png="$OUT/$(basename "${name%.vdb}")_$view.png"
    "$ATLAS" preview "$WORK/$name" --view "$view" --size "$SIZE" --quiet -o "$png"
    pics+=("$png")
  done
  "$ATLAS" preview "$PACK/example1/tga/modeling_data(0).tga" "$PACK/example1/tga/field_data.001.tga" --voxel 8 --view "$view" \
    --size "$SIZE" --quiet -o "$OUT/pack_parkouring_$view.png"
  "$ATLAS" preview "$PACK/example2/tga/modeling_data(0).tga" "$PACK/example2/tga/field_data(0).tga" --voxel 8 --view "$view" \
    --size "$SIZE" --quiet -o "$OUT/pack_stormbird_$view.png"
  pics+=("$OUT/pack_parkouring_$view.png" "$OUT/pack_stormbird_$view.png")
  oiiotool "${pics[@]}" --mosaic 5x1 -o "$OUT/compare_$view.png"
done
ls -l "$OUT"/compare_*.png

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
# At a glance, in numbers: how bright each cloud is and how dark its shadows go (8-bit
# luminance over the cloud's pixels: those differing from their row's median sky by
# more than 6/255), read back with OpenImageIO.
/usr/bin/python3 - "$OUT" <<'EOF'
import glob, os, sys
import numpy as np
import OpenImageIO as oiio
print(f"{'picture':34s} {'cloud %':>8s} {'mean':>6s} {'p10':>6s} {'p90':>6s}")
for path in sorted(glob.glob(os.path.join(sys.argv[1], "*_*.png"))):
    if os.path.basename(path).startswith("compare_"):
        continue
    px = np.round(oiio.ImageBuf(path).get_pixels(oiio.FLOAT)[..., :3] * 255.0)
    cloud = np.abs(px - np.median(px, axis=1, keepdims=True)).max(axis=2) > 6
    lum = (px @ np.array([0.2126, 0.7152, 0.0722]))[cloud]
    if lum.size == 0:
        print(f"{os.path.basename(path):34s} {0:8.1f}      -      -      -")
        continue
    p10, p90 = np.percentile(lum, [10, 90])
    print(f"{os.path.basename(path):34s} {100 * cloud.mean():8.1f} {lum.mean():6.0f} {p10:6.0f} {p90:6.0f}")
EOF
ls -l "$OUT"/compare_*.png

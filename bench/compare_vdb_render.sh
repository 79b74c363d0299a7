#!/usr/bin/env bash
# Atlas preview vs OpenVDB's vdb_render on graphs/cloudscape.yaml (not in CI).
#
#   bench/compare_vdb_render.sh [BUILD_DIR]      (default: build)
#
# Needs vdb_render (Debian libopenvdb-tools) and oiiotool (openimageio-tools).
# 1. Cooks the cloudscape's density to a VDB: a copy of the graph with one
#    extra node, the eroded metaball density remapped from its 0.3 iso level
#    to [0, 1] (vdb_render shows every non-zero voxel, and the cloudscape's
#    surfaces sit at 0.3), written as density.vdb (float grid "density", 8 m
#    voxels, world metres).
# 2. Renders 960x540 from the benchmark's ground camera with both renderers in
#    the same run and times each render (Atlas: its own "rendered ... in" line,
#    the NVDF set coming from the disk cache; vdb_render: wall time of the
#    process, which includes reading the 512x512x64 grid).
# 3. Writes docs/images/render_vdb_ground.png and render_atlas_ground_cmp.png
#    and prints a Markdown table row.
#
# Camera translation: Atlas --camera P,L --fov V (vertical degrees) ->
# vdb_render -translate P -lookat L -up 0,0,1 -fov H with H the horizontal
# field of view, H = 2 atan(tan(V/2) * W/H) (vdb_render's fov is the film
# aperture's, which is horizontal). Sun: Atlas --sun 60,35 (toward the sun)
# -> -light with the same unit vector. Coefficients: vdb_render's -absorb and
# -scatter are per unit of *index* space (one voxel = 8 m), so Atlas'
# extinction 0.04 / m at density 1 is 0.32 per voxel: scatter 0.30 +
# absorb 0.02. A picture that comes out black usually means coefficients per
# metre (100x too thin) or per voxel far too high, a camera not looking at the
# volume (-up must be 0,0,1: z is up), or the wrong grid.
set -euo pipefail

ROOT=$(cd "$(dirname "$0")/.." && pwd)
BUILD=${1:-$ROOT/build}
ATLAS=$BUILD/bin/atlas
command -v vdb_render >/dev/null || { echo "vdb_render not found (scripts/setup.sh --bench installs libopenvdb-tools)" >&2; exit 1; }
command -v oiiotool >/dev/null || { echo "oiiotool not found (apt install openimageio-tools)" >&2; exit 1; }
[ -x "$ATLAS" ] || { echo "$ATLAS not found: build the atlas target first" >&2; exit 1; }

WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
CACHE=${ATLAS_CACHE_DIR:-$WORK/cache}
OUT_DIR=$ROOT/docs/images

W=960 H=540
CAM_POS=2000,-300,2 CAM_AT=2000,2000,300 VFOV=60
SUN_AZ=60 SUN_EL=35
HFOV=$(python3 -c "import math; print(round(math.degrees(2*math.atan(math.tan(math.radians($VFOV/2))*$W/$H)), 4))")
LIGHT=$(python3 -c "import math; a,e=math.radians($SUN_AZ),math.radians($SUN_EL); print(f'{math.cos(e)*math.sin(a):.5f},{-math.cos(e)*math.cos(a):.5f},{math.sin(e):.5f}')")

# 1. The cloudscape plus a density output.
awk '
  /^outputs:/ && !done {
    print "  vdb_density:                        # compare_vdb_render.sh: density from the 0.3 iso level up"
    print "    type: math/remap"
    print "    inputs: {in: eroded}"
    print "    params: {in_min: 0.3, in_max: 1, out_min: 0, out_max: 1, clamp: true}"
    print ""
    done = 1
  }
  { print }
  END {
    print "  - node: vdb_density"
    print "    file: density.vdb"
  }' "$ROOT/graphs/cloudscape.yaml" > "$WORK/cloudscape_vdb.yaml"
"$ATLAS" cook "$WORK/cloudscape_vdb.yaml" --out "$WORK/out" --output density.vdb --cache "$CACHE" --quiet >/dev/null
"$ATLAS" info "$WORK/out/density.vdb" >&2

# 2a. Atlas: the graph's NVDF set (same cache), default quality.
ATLAS_LOG=$("$ATLAS" preview "$ROOT/graphs/cloudscape.yaml" --cache "$CACHE" --size ${W}x${H} \
  --camera $CAM_POS,$CAM_AT --fov $VFOV --sun $SUN_AZ,$SUN_EL -o "$OUT_DIR/render_atlas_ground_cmp.png" 2>&1 >/dev/null)
echo "$ATLAS_LOG" >&2
ATLAS_S=$(echo "$ATLAS_LOG" | sed -n 's/.*rendered [0-9x]* in \([0-9.]*\) s.*/\1/p')

# 2b. vdb_render, same camera and sun.
T0=$(date +%s.%N)
vdb_render "$WORK/out/density.vdb" "$WORK/vdb.exr" -name density -res ${W}x${H} \
  -translate $CAM_POS -lookat $CAM_AT -up 0,0,1 -fov $HFOV \
  -light $LIGHT,1,0.95,0.88 -scatter 0.30,0.30,0.30 -absorb 0.02,0.02,0.02 -gain 0.2 -step 1 -shadowstep 3 -v >&2
T1=$(date +%s.%N)
VDB_S=$(python3 -c "print(f'{$T1 - $T0:.2f}')")
# vdb_render's EXR has straight colour plus alpha: composite over the same
# uniform sky Atlas uses (0.30, 0.45, 0.75) and tone-map like Atlas' PNG
# (x * 1.5, Reinhard, sRGB) so the two pictures are comparable.
oiiotool "$WORK/vdb.exr" --ch R,G,B,A --unpremult --premult \
  --pattern constant:color=0.30,0.45,0.75,1 ${W}x${H} 4 --over \
  --ch R,G,B --mulc 1.5 --dup --addc 1 --div --colorconvert linear sRGB -d uint8 --nosoftwareattrib -o "$OUT_DIR/render_vdb_ground.png"

echo "| renderer | picture | seconds |"
echo "|---|---|---|"
echo "| atlas preview (fast, quality 1, NVDF set) | render_atlas_ground_cmp.png | $ATLAS_S (render only) |"
echo "| vdb_render (density.vdb, step 1 voxel, shadow step 3) | render_vdb_ground.png | $VDB_S (process, incl. VDB read) |"

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
#    the same run, both reading the same density.vdb, interleaved (atlas
#    --noise none, atlas with its default noise up-rez, vdb_render, ... ROUNDS
#    times, default 3), each whole process timed by /usr/bin/time -f
#    '%e %U %S %M' (wall s, user and system CPU s, max RSS KB). `atlas preview
#    density.vdb --noise none` is the like-for-like row (vdb_render does no
#    up-rez); the default row adds the Nubis noise set (noise/nubis_set 128^3,
#    from a warm cache: one untimed run first cooks it). Atlas's render-only
#    time is from its "rendered ... in" line, vdb_render's ray-tracing time
#    from its -v output; both include reading the 512x512x64 grid.
# 3. Writes docs/images/render_vdb_ground.png and render_atlas_density_cmp.png
#    (the like-for-like Atlas run) and prints a Markdown table: one row per run
#    plus the medians, and `atlas --help`'s own cost (process start: shared
#    libraries) for scale.
# ATLAS_BASE=/path/to/older/atlas adds that binary's `--noise none` run to
#    every round (interleaved, same file and camera), for before/after figures
#    under the same load, and says whether its picture has the same bytes.
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
ROUNDS=${ROUNDS:-3}
PY=/usr/bin/python3
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
HFOV=$($PY -c "import math; print(round(math.degrees(2*math.atan(math.tan(math.radians($VFOV/2))*$W/$H)), 4))")
LIGHT=$($PY -c "import math; a,e=math.radians($SUN_AZ),math.radians($SUN_EL); print(f'{math.cos(e)*math.sin(a):.5f},{-math.cos(e)*math.cos(a):.5f},{math.sin(e):.5f}')")

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

# 2. Both renderers, same density file, camera and sun, whole processes timed, interleaved.
ATLAS_CMD=("$ATLAS" preview "$WORK/out/density.vdb" --cache "$CACHE" --size ${W}x${H}
  --camera $CAM_POS,$CAM_AT --fov $VFOV --sun $SUN_AZ,$SUN_EL)
VDB_CMD=(vdb_render "$WORK/out/density.vdb" "$WORK/vdb.exr" -name density -res ${W}x${H}
  -translate $CAM_POS -lookat $CAM_AT -up 0,0,1 -fov $HFOV
  -light $LIGHT,1,0.95,0.88 -scatter 0.30,0.30,0.30 -absorb 0.02,0.02,0.02 -gain 0.2 -step 1 -shadowstep 3 -v)
"${ATLAS_CMD[@]}" -o "$WORK/warm.png" --quiet >/dev/null 2>&1   # warm the cache (noise set): not timed
/usr/bin/time -f '%e %U %S %M' -o "$WORK/t_help" "$ATLAS" --help >/dev/null 2>&1 || true
ATLAS_BASE=${ATLAS_BASE:-}
if [ -n "$ATLAS_BASE" ]; then
  BASE_CMD=("$ATLAS_BASE" "${ATLAS_CMD[@]:1}")
  "${BASE_CMD[@]}" -o "$WORK/warm_base.png" --quiet >/dev/null 2>&1
  /usr/bin/time -f '%e %U %S %M' -o "$WORK/t_help_base" "$ATLAS_BASE" --help >/dev/null 2>&1 || true
fi
ROWS=()
BASE_ROWS=()
atlas_run() { # $1 = none | auto, $2 = output picture, $3 = tag
  /usr/bin/time -f '%e %U %S %M' -o "$WORK/t_$3" "${ATLAS_CMD[@]}" --noise "$1" -o "$2" >/dev/null 2>"$WORK/log_$3"
}
for r in $(seq 1 "$ROUNDS"); do
  atlas_run none "$OUT_DIR/render_atlas_density_cmp.png" none
  atlas_run auto "$WORK/atlas_auto.png" auto
  /usr/bin/time -f "%e %U %S %M" -o "$WORK/t_vdb" "${VDB_CMD[@]}" >"$WORK/log_vdb" 2>&1
  if [ -n "$ATLAS_BASE" ]; then
    /usr/bin/time -f '%e %U %S %M' -o "$WORK/t_base" "${BASE_CMD[@]}" --noise none -o "$WORK/atlas_base.png" >/dev/null 2>&1
    BASE_ROWS+=("$r $(cat "$WORK/t_base")")
    echo "round $r: baseline atlas --noise none $(cat "$WORK/t_base") (wall s, user s, sys s, max RSS KB)" >&2
  fi
  N_RENDER=$(sed -n 's/.*rendered [0-9x]*[^)]*) in \([0-9.]*\) s.*/\1/p' "$WORK/log_none" | tail -1)
  A_RENDER=$(sed -n 's/.*rendered [0-9x]*[^)]*) in \([0-9.]*\) s.*/\1/p' "$WORK/log_auto" | tail -1)
  V_RENDER=$(awk '/ray-tracing/ {f = 1; next} f && /completed in/ {print $(NF - 1); exit}' "$WORK/log_vdb")
  read -r NW NU NS NM < "$WORK/t_none"
  read -r AW AU AS AM < "$WORK/t_auto"
  read -r VW VU VS VM < "$WORK/t_vdb"
  ROWS+=("$r $NW $NU $NS $NM ${N_RENDER:-?} $AW $AU $AS $AM ${A_RENDER:-?} $VW $VU $VS $VM ${V_RENDER:-?}")
  echo "round $r: atlas --noise none ${NW}s wall ${NU}+${NS}s CPU ${NM}KB (render ${N_RENDER:-?} s); default noise ${AW}s ${AU}+${AS}s ${AM}KB (render ${A_RENDER:-?} s); vdb_render ${VW}s wall ${VU}+${VS}s CPU ${VM}KB (ray-tracing ${V_RENDER:-?} s)" >&2
done
cat "$WORK/log_none" "$WORK/log_auto" >&2
# vdb_render's EXR has straight colour plus alpha: composite over the same
# uniform sky Atlas uses (0.30, 0.45, 0.75) and tone-map like Atlas' PNG
# (x * 1.5, Reinhard, sRGB) so the two pictures are comparable.
oiiotool "$WORK/vdb.exr" --ch R,G,B,A --unpremult --premult \
  --pattern constant:color=0.30,0.45,0.75,1 ${W}x${H} 4 --over \
  --ch R,G,B --mulc 1.5 --dup --addc 1 --div --colorconvert linear sRGB -d uint8 --nosoftwareattrib -o "$OUT_DIR/render_vdb_ground.png"

echo "load average after the runs: $(cat /proc/loadavg)"
echo
read -r HW HU HS HM < "$WORK/t_help"
echo "| round | atlas (--noise none) wall | user + sys CPU | max RSS | render only | atlas (default noise) wall | user + sys CPU | max RSS | render only | vdb_render wall | user + sys CPU | max RSS | ray-tracing |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|"
for row in "${ROWS[@]}"; do
  set -- $row
  echo "| $1 | $2 s | $3 + $4 s | $(( $5 / 1024 )) MB | $6 s | $7 s | $8 + $9 s | $(( ${10} / 1024 )) MB | ${11} s | ${12} s | ${13} + ${14} s | $(( ${15} / 1024 )) MB | ${16} s |"
done
printf '%s\n' "${ROWS[@]}" | $PY -c '
import sys, statistics as st
rows = [l.split() for l in sys.stdin if l.strip()]
col = lambda i: st.median(float(r[i]) for r in rows)
cells = lambda b: f"{col(b):.2f} s | {col(b + 1):.2f} + {col(b + 2):.2f} s | {col(b + 3)/1024:.0f} MB | -"
print(f"| median | {cells(1)} | {cells(6)} | {cells(11)} |")'
echo
echo "atlas --help alone (process start, $(ldd "$ATLAS" | wc -l) shared libraries): ${HW} s wall, ${HU} + ${HS} s CPU, $(( HM / 1024 )) MB max RSS"
if [ -n "$ATLAS_BASE" ]; then
  echo
  echo "| baseline (--noise none) | wall | user + sys CPU | max RSS |"
  echo "|---|---|---|---|"
  printf '%s\n' "${BASE_ROWS[@]}" | $PY -c '
import sys, statistics as st
rows = [l.split() for l in sys.stdin if l.strip()]
for r in rows: print(f"| {r[0]} | {float(r[1]):.2f} s | {float(r[2]):.2f} + {float(r[3]):.2f} s | {int(r[4])//1024} MB |")
col = lambda i: st.median(float(r[i]) for r in rows)
print(f"| median | {col(1):.2f} s | {col(2):.2f} + {col(3):.2f} s | {col(4)/1024:.0f} MB |")'
  read -r BW BU BS BM < "$WORK/t_help_base"
  echo "baseline $ATLAS_BASE --help ($(ldd "$ATLAS_BASE" | wc -l) shared libraries): ${BW} s wall, ${BU} + ${BS} s CPU, $(( BM / 1024 )) MB max RSS"
  if cmp -s "$WORK/atlas_base.png" "$OUT_DIR/render_atlas_density_cmp.png"; then echo "baseline picture: the same bytes"; else echo "baseline picture: DIFFERENT bytes"; fi
fi
echo "atlas: density.vdb read as a plain density grid (render::load_scene), fast mode, quality 1; pictures render_atlas_density_cmp.png (--noise none), render_vdb_ground.png"

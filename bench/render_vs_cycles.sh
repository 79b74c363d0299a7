#!/usr/bin/env bash
# The voxel preview's luminance error against Blender's Cycles, and Cycles' own error against
# its converged image per sample count (docs/render.md, "Reference: Cycles").
#
#   bench/render_vs_cycles.sh [--smoke] [--build DIR] [--out DIR] [--size WxH] [--ref-spp N] [--bounces N] [--reuse-ref] [--ladder "1 4 .."]
#
# Per scene: atlas preview --artistic off --export-scene (the scene for Cycles), then
#   - Cycles with --ref-spp samples (default 512) and --bounces volume bounces (default 1024: at
#     128 the thick scenes lose 2-9% of their light to the cut-off paths): the reference;
#   - the preview at its defaults (--artistic off and on), across --quality (march steps)
#     and --light-grid (the sun's light grid), the octaves without the diffusion term
#     (--ms-diffusion off) and single scattering (--ms-octaves 0);
#   - Cycles at 1, 4, 16, 64 samples (another seed): its error and time.
# Writes OUT/results.csv, OUT/table.md and docs/images/cycles_error_vs_time.png (matplotlib).
# --smoke: one scene, 64x36, 8 reference samples, no plot (CI: checks the pipeline runs).
# --reuse-ref: keep OUT/SCENE/cycles_ref.exr when its stats say --ref-spp samples and --bounces (a converged
# 1024+ spp reference takes minutes; render it once, at nice -n 10, off CI).
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
BUILD=$ROOT/build
OUT=$ROOT/build/render_vs_cycles
SIZE=160x90
REF_SPP=512
BOUNCES=1024
SMOKE=0
REUSE=0
LADDER="1 4 16 64"
while [ $# -gt 0 ]; do
  case $1 in
    --smoke) SMOKE=1; shift ;;
    --build) BUILD=$2; shift 2 ;;
    --out) OUT=$2; shift 2 ;;
    --size) SIZE=$2; shift 2 ;;
    --ref-spp) REF_SPP=$2; shift 2 ;;
    --bounces) BOUNCES=$2; shift 2 ;;
    --reuse-ref) REUSE=1; shift ;;
    --ladder) LADDER=$2; shift 2 ;;
    *) echo "unknown option $1" >&2; exit 2 ;;
  esac
done
ATLAS=$BUILD/bin/atlas
PY=/usr/bin/python3
if ! command -v blender > /dev/null; then echo "render_vs_cycles: blender not found (scripts/setup.sh installs it)" >&2; exit 77; fi
# name|atlas preview arguments
SCENES=(
  "quickstart|$ROOT/examples/quickstart.yaml"
  "cloudscape|$ROOT/graphs/cloudscape.yaml"
  "quickstart_thin|$ROOT/examples/quickstart.yaml --extinction 0.008"
)
if [ $SMOKE = 1 ]; then SIZE=64x36; REF_SPP=8; BOUNCES=128; LADDER="1"; SCENES=("${SCENES[0]}"); fi
mkdir -p "$OUT"
CSV=$OUT/results.csv
echo "scene,renderer,setting,seconds,mean_rel,rmse,cloud_mean_rel,cloud_rmse,cloud_bias" > "$CSV"
echo "render_vs_cycles: $(date -u), load $(cat /proc/loadavg)" >&2

cycles() { # DIR OUT SPP SEED [extra] -> prints wall seconds
  local d=$1 o=$2 n=$3 seed=$4; shift 4
  blender -b --factory-startup --python-exit-code 1 --python "$ROOT/scripts/cycles_reference.py" -- "$d" "$o" \
    --samples "$n" --bounces "$BOUNCES" --seed "$seed" --threads 2 --stats "$o.json" "$@" > "$o.log" 2>&1
  $PY -c "import json; print('%.2f' % json.load(open('$o.json'))['seconds'])"
}
atlas() { # OUT args... -> prints render seconds (the CLI's summary line)
  local o=$1; shift
  "$ATLAS" preview "$@" --size "$SIZE" --cache "$OUT/cache" -o "$o" 2> "$o.log" > /dev/null
  sed -n 's/.*rendered [0-9x]* (voxel) in \([0-9.]*\) s.*/\1/p' "$o.log" | tail -1
}
row() { # scene renderer setting seconds image reference
  local m
  m=$($PY "$ROOT/scripts/render_compare.py" "$5" "$6" --json)
  $PY -c "import json,sys; m=json.loads(sys.argv[1]); print(','.join(['$1','$2','$3','$4']+['%.4f'%m.get(k,float('nan')) for k in ('mean_rel','rmse','cloud_mean_rel','cloud_rmse','cloud_bias')]))" "$m" >> "$CSV"
}

for entry in "${SCENES[@]}"; do
  name=${entry%%|*}; args=${entry#*|}
  d=$OUT/$name; mkdir -p "$d"
  # shellcheck disable=SC2086
  t=$(atlas "$d/physical_default.exr" $args --artistic off --export-scene "$d/scene")
  ref=$d/cycles_ref.exr
  if [ $REUSE = 1 ] && [ -f "$ref" ] && [ "$($PY -c "import json; j = json.load(open('$ref.json')); print(j['samples'], j.get('bounces', 128))" 2>/dev/null)" = "$REF_SPP $BOUNCES" ]; then
    tref=$($PY -c "import json; print('%.2f' % json.load(open('$ref.json'))['seconds'])")
  else
    tref=$(cycles "$d/scene" "$ref" "$REF_SPP" 0)
  fi
  echo "$name: cycles reference $REF_SPP spp in $tref s" >&2
  row "$name" cycles "$REF_SPP spp (reference)" "$tref" "$ref" "$ref"
  row "$name" atlas "artistic off; defaults" "$t" "$d/physical_default.exr" "$ref"
  # shellcheck disable=SC2086
  t=$(atlas "$d/artistic_on.exr" $args --artistic on --export-scene "$d/scene_on")
  row "$name" atlas "artistic on (the look); defaults" "$t" "$d/artistic_on.exr" "$ref"
  if [ $SMOKE = 0 ]; then
    for q in 0.5 2 4; do
      # shellcheck disable=SC2086
      t=$(atlas "$d/q$q.exr" $args --artistic off --quality $q --export-scene "$d/scene_q")
      row "$name" atlas "artistic off; quality $q" "$t" "$d/q$q.exr" "$ref"
    done
    for g in 32,32,8 64,64,16; do
      # shellcheck disable=SC2086
      t=$(atlas "$d/g$g.exr" $args --artistic off --light-grid $g --export-scene "$d/scene_g")
      row "$name" atlas "artistic off; light grid ${g//,/x}" "$t" "$d/g$g.exr" "$ref"
    done
    # shellcheck disable=SC2086
    t=$(atlas "$d/octaves.exr" $args --artistic off --ms-diffusion off --export-scene "$d/scene_oct")
    row "$name" atlas "artistic off; octaves only (no diffusion)" "$t" "$d/octaves.exr" "$ref"
    # shellcheck disable=SC2086
    t=$(atlas "$d/ss.exr" $args --artistic off --ms-octaves 0 --export-scene "$d/scene_ss")
    row "$name" atlas "artistic off; single scattering" "$t" "$d/ss.exr" "$ref"
  fi
  for n in $LADDER; do
    t=$(cycles "$d/scene" "$d/cycles_$n.exr" "$n" 7)
    # the Cycles image has no transmittance channel: the cloud mask is the preview's
    $PY -c "
import sys; sys.path.insert(0, '$ROOT/scripts')
import render_compare as rc
m = rc.metrics(rc.luminance('$d/cycles_$n.exr'), rc.luminance('$ref'), cloud=rc.cloud_mask('$d/physical_default.exr'))
print(','.join(['$name', 'cycles', '$n spp', '$t'] + ['%.4f' % m.get(k, float('nan')) for k in ('mean_rel', 'rmse', 'cloud_mean_rel', 'cloud_rmse', 'cloud_bias')]))
" >> "$CSV"
  done
  echo "$name: done" >&2
done

if [ "$SMOKE" = 1 ]; then
  $PY "$ROOT/scripts/error_vs_time_plot.py" "$CSV" "$OUT/table.md"
else
  $PY "$ROOT/scripts/error_vs_time_plot.py" "$CSV" "$OUT/table.md" "$ROOT/docs/images/cycles_error_vs_time.png"
fi

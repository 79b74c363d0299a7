#!/usr/bin/env bash
# The 2.5D preview's luminance error against Blender's Cycles (docs/render.md, "2.5D against Cycles").
#
#   bench/render_vs_cycles_layer.sh [--build DIR] [--out DIR] [--size WxH] [--ref-spp N] [--ref-seeds K] [--bounces N] [--ladder "1 4 .."] [--reuse-ref]
#
# Per graph (superstorm: --view orbit:30,25; hzd_weather, fc6_forecast: the same with --fov 20): atlas preview
# --artistic off --export-scene bakes the layer's density over a 16 km patch under the camera's
# look-at point (the preview then draws only that patch, without haze, rain absorption or sky
# layers); the same at --extinction 0 gives the preview's background (sky and ground); Cycles
# renders the patch with a transparent film (--alpha), composited over that background by
# render_compare.py --background. The reference: --ref-spp samples, --bounces volume bounces
# (default 1024: at 128 the superstorm loses ~6% of its light to the cut-off paths), the mean of
# --ref-seeds independent renders (seeds 0..K-1, default 4: one 1024-spp render is ~4% from the
# others per pixel, which the preview's error would carry; the row "one seed against the others"
# gives that noise). --reuse-ref keeps OUT's renders whose samples and bounces match. Rows: Cycles reference, Atlas artistic off / on, Atlas quality
# 0.5 / 2, light grid 64,64,16 / 192,192,48, no diffusion, Cycles at the ladder's sample counts
# (seed 7). Writes OUT/results.csv, OUT/table.md, docs/images/cycles_layer_error_vs_time.png and
# docs/images/cycles_layer_compare.png (each scene's default preview, the reference, their ratio).
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
BUILD=$ROOT/build
OUT=$ROOT/build/render_vs_cycles_layer
SIZE=160x90
REF_SPP=1024
REF_SEEDS=4
BOUNCES=1024
LADDER="1 4 16 64 256"
REUSE=0
while [ $# -gt 0 ]; do
  case $1 in
    --build) BUILD=$2; shift 2 ;;
    --out) OUT=$2; shift 2 ;;
    --size) SIZE=$2; shift 2 ;;
    --ref-spp) REF_SPP=$2; shift 2 ;;
    --ref-seeds) REF_SEEDS=$2; shift 2 ;;
    --bounces) BOUNCES=$2; shift 2 ;;
    --ladder) LADDER=$2; shift 2 ;;
    --reuse-ref) REUSE=1; shift ;;
    *) echo "unknown option $1" >&2; exit 2 ;;
  esac
done
ATLAS=$BUILD/bin/atlas
PY=/usr/bin/python3
if ! command -v blender > /dev/null; then echo "render_vs_cycles_layer: blender not found (scripts/setup.sh installs it)" >&2; exit 77; fi
mkdir -p "$OUT"
CSV=$OUT/results.csv
echo "scene,renderer,setting,seconds,mean_rel,rmse,cloud_mean_rel,cloud_rmse,cloud_bias" > "$CSV"
echo "render_vs_cycles_layer: $(date -u), load $(cat /proc/loadavg)" >&2
cycles() { # DIR OUT SPP SEED -> prints wall seconds
  local d=$1 o=$2 n=$3 seed=$4
  blender -b --factory-startup --python-exit-code 1 --python "$ROOT/scripts/cycles_reference.py" -- "$d" "$o" \
    --samples "$n" --bounces "$BOUNCES" --seed "$seed" --threads 2 --alpha --stats "$o.json" > "$o.log" 2>&1
  $PY -c "import json; print('%.2f' % json.load(open('$o.json'))['seconds'])"
}
atlas() { # OUT args... -> prints render seconds
  local o=$1; shift
  "$ATLAS" preview "$@" --size "$SIZE" --cache "$OUT/cache" -o "$o" 2> "$o.log" > /dev/null
  sed -n 's/.*rendered [0-9x]* (2.5D) in \([0-9.]*\) s.*/\1/p' "$o.log" | tail -1
}
row() { # scene renderer setting seconds image reference background mask
  $PY -c "
import sys; sys.path.insert(0, '$ROOT/scripts')
import render_compare as rc
ref = rc.composite_luminance('$6', '$7')
y = rc.composite_luminance('$5', '$7') if '$5'.endswith('.cycles.exr') else rc.luminance('$5')
m = rc.metrics(y, ref, cloud=rc.cloud_mask('$8'))
print(','.join(['$1', '$2', '$3', '$4'] + ['%.4f' % m.get(k, float('nan')) for k in ('mean_rel', 'rmse', 'cloud_mean_rel', 'cloud_rmse', 'cloud_bias')]))
" >> "$CSV"
}
for name in superstorm hzd_weather fc6_forecast; do
  # the orbit camera frames the whole map; the weather maps zoom in on the patch
  FOV=""; [ $name = superstorm ] || FOV="--fov 20"
  d=$OUT/$name; mkdir -p "$d"
  g=$ROOT/graphs/$name.yaml
  t=$(atlas "$d/physical_default.exr" "$g" --view orbit:30,25 $FOV --artistic off --export-scene "$d/scene")
  atlas "$d/background.exr" "$g" --view orbit:30,25 $FOV --artistic off --extinction 0 --export-scene "$d/scene_bg" > /dev/null
  # The reference: seed 0 in ref.cycles.exr, seed k in ref_seed<k>.cycles.exr, their mean in ref_mean.cycles.exr.
  refs=() tref=0
  for ((k = 0; k < REF_SEEDS; ++k)); do
    r=$d/ref.cycles.exr; [ $k = 0 ] || r=$d/ref_seed$k.cycles.exr
    if [ $REUSE = 1 ] && [ -f "$r" ] && [ "$($PY -c "import json; j = json.load(open('$r.json')); print(j['samples'], j.get('bounces', 128))" 2>/dev/null)" = "$REF_SPP $BOUNCES" ]; then
      tr=$($PY -c "import json; print('%.2f' % json.load(open('$r.json'))['seconds'])")
    else
      tr=$(cycles "$d/scene" "$r" "$REF_SPP" $k)
    fi
    tref=$($PY -c "print('%.2f' % ($tref + $tr))")
    [ $k != 0 ] || t0=$tr
    refs+=("$r")
  done
  ref=$d/ref_mean.cycles.exr
  $PY -c "import sys; sys.path.insert(0, '$ROOT/scripts'); import render_compare as rc; rc.average_images(sys.argv[1:], '$ref')" "${refs[@]}"
  echo "$name: cycles reference $REF_SEEDS x $REF_SPP spp in $tref s; $(grep -o 'exported.*voxels of [0-9.]* m' "$d/physical_default.exr.log")" >&2
  mask=$d/physical_default.exr
  row "$name" cycles "$REF_SEEDS x $REF_SPP spp (reference)" "$tref" "$ref" "$ref" "$d/background.exr" "$mask"
  if [ "$REF_SEEDS" -gt 1 ]; then # the reference's own noise: seed 0 against the mean of the others
    $PY -c "import sys; sys.path.insert(0, '$ROOT/scripts'); import render_compare as rc; rc.average_images(sys.argv[1:], '$d/ref_others.cycles.exr')" "${refs[@]:1}"
    row "$name" cycles "$REF_SPP spp seed 0 against the mean of the other seeds (the reference noise)" "$t0" "${refs[0]}" "$d/ref_others.cycles.exr" "$d/background.exr" "$mask"
  fi
  row "$name" atlas "artistic off; defaults" "$t" "$d/physical_default.exr" "$ref" "$d/background.exr" "$mask"
  t=$(atlas "$d/artistic_on.exr" "$g" --view orbit:30,25 $FOV --artistic on --export-scene "$d/scene_on")
  row "$name" atlas "artistic on (the look); defaults" "$t" "$d/artistic_on.exr" "$ref" "$d/background.exr" "$mask"
  for q in 0.5 2; do
    t=$(atlas "$d/q$q.exr" "$g" --view orbit:30,25 $FOV --artistic off --quality $q --export-scene "$d/scene_q")
    row "$name" atlas "artistic off; quality $q" "$t" "$d/q$q.exr" "$ref" "$d/background.exr" "$mask"
  done
  for lg in 64,64,16 192,192,48; do
    t=$(atlas "$d/lg$lg.exr" "$g" --view orbit:30,25 $FOV --artistic off --light-grid $lg --export-scene "$d/scene_lg")
    row "$name" atlas "artistic off; light grid ${lg//,/x}" "$t" "$d/lg$lg.exr" "$ref" "$d/background.exr" "$mask"
  done
  t=$(atlas "$d/octaves.exr" "$g" --view orbit:30,25 $FOV --artistic off --ms-diffusion off --export-scene "$d/scene_oct")
  row "$name" atlas "artistic off; octaves only (no diffusion)" "$t" "$d/octaves.exr" "$ref" "$d/background.exr" "$mask"
  for n in $LADDER; do
    t=$(cycles "$d/scene" "$d/l$n.cycles.exr" "$n" 7)
    row "$name" cycles "$n spp" "$t" "$d/l$n.cycles.exr" "$ref" "$d/background.exr" "$mask"
  done
  echo "$name: done" >&2
done
$PY "$ROOT/scripts/error_vs_time_plot.py" "$CSV" "$OUT/table.md" "$ROOT/docs/images/cycles_layer_error_vs_time.png"
# The default preview beside the reference, per scene, and where it is brighter or darker.
$PY -c "
import sys; sys.path.insert(0, '$ROOT/scripts')
import render_compare as rc
rows = []
for name in ('superstorm', 'hzd_weather', 'fc6_forecast'):
    d = '$OUT/' + name
    rows.append((rc.luminance(d + '/physical_default.exr'), rc.composite_luminance(d + '/ref_mean.cycles.exr', d + '/background.exr'),
                 rc.cloud_mask(d + '/physical_default.exr')))
rc.comparison_rows(rows, '$ROOT/docs/images/cycles_layer_compare.png')
"
echo "wrote $ROOT/docs/images/cycles_layer_compare.png" >&2

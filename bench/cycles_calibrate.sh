#!/usr/bin/env bash
# Calibration of the physical preview's multiple scattering against Cycles on uniform shapes
# (docs/render.md, "Calibration against Cycles").
#
#   bench/cycles_calibrate.sh [--build DIR] [--out DIR] [--spp N] [--size WxH] [--refs-only] [--sweep "SPEC..."]
#
# Shapes (scripts/calibration_shapes.py): a 1 km box and a 1 km sphere of uniform density, at
# extinction 0.001, 0.004, 0.016 /m (optical thickness 1, 4, 16 across), lit from the camera's side
# (the default sun) and from the side (--sun 120,35). Per case: atlas preview --artistic off
# --export-scene, one Cycles reference (--spp samples, 128 volume bounces; kept if present), then the
# preview for each sweep spec (extra atlas preview arguments, ';'-separated) and its errors.
# Writes OUT/calibration.csv (case, spec, cloud mean rel., cloud bias, mean rel.) and prints the
# mean over the cases per spec, best first.
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
BUILD=$ROOT/build
OUT=$ROOT/build/cycles_calibration
SPP=256
SIZE=64x36
REFS_ONLY=0
SWEEP="--ms-octaves 8"
while [ $# -gt 0 ]; do
  case $1 in
    --build) BUILD=$2; shift 2 ;;
    --out) OUT=$2; shift 2 ;;
    --spp) SPP=$2; shift 2 ;;
    --size) SIZE=$2; shift 2 ;;
    --refs-only) REFS_ONLY=1; shift ;;
    --sweep) SWEEP=$2; shift 2 ;;
    *) echo "unknown option $1" >&2; exit 2 ;;
  esac
done
ATLAS=$BUILD/bin/atlas
PY=/usr/bin/python3
if ! command -v blender > /dev/null; then echo "cycles_calibrate: blender not found (scripts/setup.sh installs it)" >&2; exit 77; fi
mkdir -p "$OUT"
[ -f "$OUT/box.vdb" ] || $PY "$ROOT/scripts/calibration_shapes.py" "$OUT" > /dev/null
echo "cycles_calibrate: $(date -u), load $(cat /proc/loadavg)" >&2
CASES=()
for shape in box sphere; do
  for ext in 0.001 0.004 0.016; do
    for sun in front side; do CASES+=("$shape|$ext|$sun"); done
  done
done
sunarg() { [ "$1" = side ] && echo "--sun 120,35" || true; }
for c in "${CASES[@]}"; do
  IFS='|' read -r shape ext sun <<< "$c"
  d=$OUT/${shape}_${ext}_$sun
  mkdir -p "$d"
  # shellcheck disable=SC2046
  "$ATLAS" preview "$OUT/$shape.vdb" --noise none --artistic off --extinction "$ext" $(sunarg "$sun") --size "$SIZE" \
    --export-scene "$d/scene" -o "$d/atlas.exr" > /dev/null 2>&1
  if [ ! -f "$d/cycles.exr" ]; then
    blender -b --factory-startup --python-exit-code 1 --python "$ROOT/scripts/cycles_reference.py" -- "$d/scene" "$d/cycles.exr" \
      --samples "$SPP" --bounces 128 --threads 2 --stats "$d/cycles.json" > "$d/cycles.log" 2>&1
    echo "$c: cycles $SPP spp in $($PY -c "import json; print('%.1f' % json.load(open('$d/cycles.json'))['seconds'])") s" >&2
  fi
done
[ $REFS_ONLY = 1 ] && exit 0
CSV=$OUT/calibration.csv
echo "case,spec,cloud_mean_rel,cloud_bias,mean_rel" > "$CSV"
IFS=';' read -ra SPECS <<< "$SWEEP"
for spec in "${SPECS[@]}"; do
  for c in "${CASES[@]}"; do
    IFS='|' read -r shape ext sun <<< "$c"
    d=$OUT/${shape}_${ext}_$sun
    # shellcheck disable=SC2046,SC2086
    "$ATLAS" preview "$OUT/$shape.vdb" --noise none --artistic off --extinction "$ext" $(sunarg "$sun") --size "$SIZE" $spec \
      -o "$d/sweep.exr" > /dev/null 2>&1
    $PY -c "
import sys; sys.path.insert(0, '$ROOT/scripts')
import render_compare as rc
m = rc.metrics(rc.luminance('$d/sweep.exr'), rc.luminance('$d/cycles.exr'), cloud=rc.cloud_mask('$d/sweep.exr'))
print('%s,%s,%.4f,%.4f,%.4f' % ('${shape}_${ext}_$sun', '$spec'.replace(',', ':'), m['cloud_mean_rel'], m['cloud_bias'], m['mean_rel']))
" >> "$CSV"
  done
done
$PY - "$CSV" <<'PYEOF'
import csv, sys, collections
rows = list(csv.DictReader(open(sys.argv[1])))
by = collections.defaultdict(list)
for r in rows:
    by[r["spec"]].append(r)
res = sorted(((sum(float(r["cloud_mean_rel"]) for r in v) / len(v), max(float(r["cloud_mean_rel"]) for r in v), k, v) for k, v in by.items()))
for mean, worst, spec, v in res:
    print(f"{mean:.4f} worst {worst:.4f}  {spec}: " + " ".join(f"{r['case']}={float(r['cloud_mean_rel']):.3f}({float(r['cloud_bias']):+.2f})" for r in v))
PYEOF

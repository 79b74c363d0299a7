#!/usr/bin/env bash
# Regenerates the pictures of docs/render.md's "Gallery: what each graph should
# look like" (docs/images/look_*.png, 640x360) with `atlas preview` at its
# defaults unless a camera is named. Usage: scripts/make_gallery.sh [ATLAS_BIN]
# (default build/bin/atlas). Cooks through $ATLAS_CACHE_DIR when set; the
# cumulus tower is grown at 64^3 first (about 40 s on the 2-core machine).
set -euo pipefail
cd "$(dirname "$0")/.."
ATLAS="${1:-build/bin/atlas}"
OUT=docs/images
WORK="$(mktemp -d)"
trap 'rm -rf "$WORK"' EXIT
P() { "$ATLAS" preview "$@" --size 640x360 --quiet; }

P examples/quickstart.yaml -o "$OUT/look_quickstart.png"
P graphs/cloudscape.yaml --camera 1900,400,2,1800,1800,300 -o "$OUT/look_cloudscape.png"
P graphs/cloudscape.yaml --camera 1100,700,60,1050,1400,330 --fov 55 -o "$OUT/look_cloudscape_cumulus.png"
P graphs/towering_cumulus.yaml -o "$OUT/look_towering_cumulus.png"
P graphs/hzd_weather.yaml -o "$OUT/look_hzd_weather.png"
P graphs/hzd_weather.yaml --camera 30000,-20000,20000,30000,60000,33000 --fov 90 -o "$OUT/look_hzd_horizon.png"
P graphs/hzd_weather.yaml --set type.out_max=0 -o "$OUT/look_hzd_stratus.png"
P graphs/superstorm.yaml -o "$OUT/look_superstorm.png"
P graphs/superstorm.yaml --camera 14000,-17000,2,14000,20000,5500 --fov 40 -o "$OUT/look_superstorm_35km.png"
P graphs/superstorm.yaml --view orbit:20,10 -o "$OUT/look_superstorm_anvil.png"
P graphs/superstorm.yaml --camera 14000,-17000,2,14000,20000,5500 --fov 40 --lightning 6,3e7,6000 --flash 0 --sun-colour 0.05,0.05,0.07 \
    --sky 0.01,0.012,0.03,0.03,0.035,0.05 --exposure 4 -o "$OUT/look_superstorm_lightning.png"
P graphs/fc6_forecast.yaml -o "$OUT/look_fc6_forecast.png"
# cumulus_cloudscape composites the solver's tower: grow it (64^3 quick cook) first.
"$ATLAS" cook graphs/cumulus_growth.yaml --out "$WORK/cumulus_out" --set 'cloud.resolution=[64,64,64]' --set cloud.dx=62.5 --quiet >/dev/null
P graphs/cumulus_cloudscape.yaml --set "tower.file=$WORK/cumulus_out/cumulus_final.vdb" -o "$OUT/look_cumulus_cloudscape.png"
ls -l "$OUT"/look_*.png

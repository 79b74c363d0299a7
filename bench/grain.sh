#!/usr/bin/env bash
# Issue 41 item 6: grain at the default quality. Each 2.5D view of docs/look.md at --quality Q
# (default 1) against the same view at --quality 16 (16x the steps), RMS /255 over the cloud
# region (pixels where either picture differs from its row's median by more than 6/255), read
# back with OpenImageIO; and each render's own seconds at Q.
#
#   bench/grain.sh ATLAS_BIN [WORK_DIR] [WxH] [Q]
#
# Time only on an otherwise idle machine (docs/PERFORMANCE.md). The 16x pictures are kept in
# WORK_DIR and reused, so a sweep of Q pays for them once.
set -euo pipefail
atlas=${1:?usage: grain.sh ATLAS_BIN [WORK_DIR] [WxH] [Q]}
work=${2:-$(mktemp -d)}
size=${3:-480x270}
quality=${4:-1}
src=$(cd "$(dirname "$0")/.." && pwd)
mkdir -p "$work/cache"
py=/usr/bin/python3

render() { # render OUT GRAPH [options...]: prints the render's own seconds
    local out=$1 graph=$2
    shift 2
    "$atlas" preview "$src/$graph" -o "$out" --size "$size" --cache "$work/cache" "$@" 2>&1 |
        sed -n 's/.*rendered [0-9x]* ([^)]*) in \([0-9.]*\) s.*/\1/p'
}
grain() { "$py" "$src/scripts/grain_rms.py" "$1" "$2"; }
printf "%-34s %8s %10s %8s\n" view "RMS/255" "region %" "seconds"
view() { # view NAME GRAPH [options...]
    local name=$1 graph=$2
    shift 2
    local ref="$work/${name}_${size}_q16.png" out="$work/${name}_${size}_q${quality}.png"
    [ -f "$ref" ] || render "$ref" "$graph" "$@" --quality 16 >/dev/null
    local t
    t=$(render "$out" "$graph" "$@" --quality "$quality")
    read -r rms region <<<"$(grain "$out" "$ref")"
    printf "%-34s %8s %10s %8s\n" "$name" "$rms" "$region" "$t"
}
storm35=(--camera 14000,-17000,2,14000,20000,5500 --fov 40)
view hzd_weather_ground graphs/hzd_weather.yaml
view hzd_weather_aerial graphs/hzd_weather.yaml --view aerial
view fc6_forecast_ground graphs/fc6_forecast.yaml
view envelope_mountain_aerial graphs/envelope_mountain.yaml --view aerial
view superstorm_37km graphs/superstorm.yaml "${storm35[@]}"
view superstorm_ground_lightning graphs/superstorm.yaml --lightning 6

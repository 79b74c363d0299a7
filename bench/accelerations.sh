#!/usr/bin/env bash
# Issue 41 item 5 at full size: each shipped graph's default view (and the 2.5D graphs' aerial
# view) with every acceleration on against off, the picture difference read back with
# OpenImageIO (mean |on - off| and its 99.9th percentile, /255) and each render's time.
# tests/look/test_accelerations.py holds the same claims on small pictures in CI.
#
#   bench/accelerations.sh ATLAS_BIN [WORK_DIR] [WxH]
#
# Time only on an otherwise idle machine (docs/PERFORMANCE.md).
set -euo pipefail
atlas=${1:?usage: accelerations.sh ATLAS_BIN [WORK_DIR] [WxH]}
work=${2:-$(mktemp -d)}
size=${3:-960x540}
src=$(cd "$(dirname "$0")/.." && pwd)
mkdir -p "$work/cache"
py=/usr/bin/python3

# render NAME GRAPH OUT [options...]: prints the render's own seconds (from the summary).
render() {
    local graph=$1 out=$2
    shift 2
    "$atlas" preview "$graph" -o "$out" --size "$size" --cache "$work/cache" "$@" 2>&1 |
        sed -n 's/.*rendered [0-9x]* ([^)]*) in \([0-9.]*\) s.*/\1/p'
}
compare() {
    "$py" - "$1" "$2" <<'EOF'
import sys, numpy as np, OpenImageIO as oiio
a, b = (oiio.ImageBuf(p).get_pixels(oiio.UINT8).astype(np.int32)[..., :3] for p in sys.argv[1:3])
d = np.abs(a - b)
print(f"{d.mean():.3f} {np.percentile(d, 99.9):.1f} {d.max()}")
EOF
}

echo "graph,view,acceleration,time_on_s,time_off_s,mean_abs_255,p99.9_255,max_255"
for name in hzd_weather envelope_mountain fc6_forecast sky_layer superstorm; do
    g="$src/graphs/$name.yaml"
    for view in default aerial; do
        v=()
        [ "$view" = default ] || v=(--view "$view")
        render "$g" "$work/warm.png" "${v[@]}" > /dev/null # cook once into the cache
        on=$(render "$g" "$work/$name-$view-on.png" --envelope on "${v[@]}")
        off=$(render "$g" "$work/$name-$view-off.png" --envelope off "${v[@]}")
        echo "$name,$view,envelope,$on,$off,$(compare "$work/$name-$view-on.png" "$work/$name-$view-off.png" | tr ' ' ',')"
    done
done
for g in "$src/graphs/towering_cumulus.yaml" "$src/graphs/cloudscape.yaml" "$src/examples/quickstart.yaml"; do
    name=$(basename "$g" .yaml)
    render "$g" "$work/warm.png" > /dev/null
    on=$(render "$g" "$work/$name-on.png")
    off=$(render "$g" "$work/$name-noskip.png" --sdf-skipping off)
    echo "$name,default,sdf_skipping,$on,$off,$(compare "$work/$name-on.png" "$work/$name-noskip.png" | tr ' ' ',')"
    off=$(render "$g" "$work/$name-marched.png" --light-lookup marched)
    echo "$name,default,light_grid,$on,$off,$(compare "$work/$name-on.png" "$work/$name-marched.png" | tr ' ' ',')"
done
echo "pictures in $work" >&2

#!/usr/bin/env bash
# compress_peers_bench --rmse compares a DDS with its source PNG the right way up (issue 49 item 0):
# an image whose top and bottom differ (white top rows, black bottom, a ramp across) is encoded
# by atlas compress (BC1 and BC4; DDS rows top down, as OpenImageIO reads them: engine_import) and
# must come back with a small error; read upside down it is about 180 steps.
#   peers_rmse_orientation.sh ATLAS PEERS_BENCH WORK
set -euo pipefail
atlas="$1" peers="$2" work="$3"
rm -rf "$work" && mkdir -p "$work"
/usr/bin/python3 - "$work/asym.png" <<'PY'
import sys, numpy as np, OpenImageIO as oiio
h, w = 64, 64
img = np.zeros((h, w, 3), np.float32)
img[: h // 2] = 1.0                                  # the top half white
img[:, :, 1] *= np.linspace(0.2, 1.0, w)[None, :]    # a ramp across in green
buf = oiio.ImageBuf(oiio.ImageSpec(w, h, 3, oiio.UINT8))
buf.set_pixels(oiio.ROI(), img)
assert buf.write(sys.argv[1]), oiio.geterror()
PY
for fmt in bc4 bc1; do
  "$atlas" compress "$work/asym.png" --format "$fmt" -o "$work/asym_$fmt.dds" --quiet > /dev/null
  line="$("$peers" --rmse "$work/asym_$fmt.dds" "$work/asym.png")"
  rmse="$(echo "$line" | awk '{print $2}')"
  echo "$fmt: $line"
  awk -v r="$rmse" 'BEGIN { exit !(r < 4) }' || { echo "FAIL: $fmt RMSE $rmse 8-bit steps: compared upside down?"; exit 1; }
done
echo "ok: the right way up"

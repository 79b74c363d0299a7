#!/usr/bin/env python3
"""docs/images/ndf_superstorm.png: the channels graphs/superstorm.yaml writes, labelled, y up.

    atlas cook graphs/superstorm.yaml --out OUT
    /usr/bin/python3 scripts/ndf_storm_sheet.py OUT docs/images/ndf_superstorm.png

Reads the EXRs with OpenImageIO; each panel is one channel scaled to the range in its label.
"""
import sys

import numpy as np
import OpenImageIO as oiio
from PIL import Image, ImageDraw

out_dir, target = sys.argv[1], sys.argv[2]


def channels(name):
    buf = oiio.ImageBuf(f"{out_dir}/{name}")
    if buf.has_error:
        sys.exit(f"ndf_storm_sheet: cannot read {out_dir}/{name}: {buf.geterror()}")
    pixels = buf.get_pixels(oiio.FLOAT)
    return {c: pixels[..., i] for i, c in enumerate(buf.spec().channelnames)}, buf.spec()


ndf, spec = channels("superstorm_ndf_set.exr")
rings, _ = channels("vortex_ring_map.exr")
anvil, _ = channels("superstorm_anvil.exr")
panels = [
    ("coverage", ndf["coverage"], 0, 1),
    ("type", ndf["type"], 0, 1),
    ("bottom_type", ndf["bottom_type"], 0, 1),
    ("superstorm_coverage", ndf["superstorm_coverage"], 0, 1),
    ("min_height [0,12.3 km]", ndf["min_height"], 0, 12300),
    ("max_height [0,12.3 km]", ndf["max_height"], 0, 12300),
    ("anvil_bias", anvil["anvil_bias"], 0, 1),
    ("vortex ring_index [-1,5]", rings["ring_index"], -1, 5),
]
size, pad, label = 256, 6, 18
cols = 4
rows = (len(panels) + cols - 1) // cols
sheet = Image.new("RGB", (cols * (size + pad) + pad, 22 + rows * (size + label + pad)), "white")
draw = ImageDraw.Draw(sheet)
draw.text((pad, 4), f"graphs/superstorm.yaml: 40 km, anvil sheet + billowed mesocyclone ({spec.width}^2), y up", fill="black")
for k, (name, values, lo, hi) in enumerate(panels):
    # OpenImageIO gives row 0 at the top of the file; field row 0 is y = 0, drawn at the bottom.
    grey = np.clip((values - lo) / (hi - lo), 0, 1)[::-1] * 255
    img = Image.fromarray(grey.astype(np.uint8)).resize((size, size), Image.NEAREST)
    x, y = pad + (k % cols) * (size + pad), 22 + (k // cols) * (size + label + pad)
    draw.text((x, y), name, fill="black")
    sheet.paste(img, (x, y + label - 4))
sheet.save(target)
print(target)

#!/usr/bin/env python3
"""Per-voxel statistics of an NVDF modeling set, ours or the Nubis pack's, for docs/look.md.

    /usr/bin/python3 scripts/nvdf_stats.py CLOUD.vdb            # volume/nvdf's vdb_set (pyopenvdb)
    /usr/bin/python3 scripts/nvdf_stats.py PACK_DIR/example1/tga  # modeling_data*.tga slices (R G B)

Prints, over the occupied voxels (profile > 0): their count, the share that is "surface"
(0 < profile < 0.5), the profile's median and 90th percentile, and the detail type and density
scale on the surface and over all occupied voxels (10th / 50th / 90th percentiles). Reads the
files with pyopenvdb or Pillow, not with Atlas.
"""
import glob
import os
import re
import sys

import numpy as np


def from_vdb(path):
    import pyopenvdb as vdb

    grids, _ = vdb.readAll(path)
    by_name = {g.name: g for g in grids}
    for name in ("dimensional_profile", "detail_type", "density_scale"):
        if name not in by_name:
            sys.exit(f"{path}: no grid '{name}' (expected volume/nvdf's vdb_set)")
    bbox = by_name["dimensional_profile"].evalActiveVoxelBoundingBox()
    lo, hi = np.array(bbox[0]), np.array(bbox[1])
    shape = tuple(int(v) for v in hi - lo + 1)
    out = []
    for name in ("dimensional_profile", "detail_type", "density_scale"):
        a = np.zeros(shape, dtype=np.float32)
        by_name[name].copyToArray(a, ijk=tuple(int(v) for v in lo))
        out.append(a)
    return out


def from_tga_slices(folder):
    from PIL import Image

    files = glob.glob(os.path.join(folder, "modeling_data*.tga"))
    if not files:
        sys.exit(f"{folder}: no modeling_data*.tga slices")
    files.sort(key=lambda f: int(re.findall(r"(\d+)", os.path.basename(f))[0]))
    a = np.stack([np.asarray(Image.open(f), dtype=np.float32) / 255.0 for f in files])
    return [a[..., 0], a[..., 1], a[..., 2]]


def pct(x):
    return " / ".join(f"{v:.2f}" for v in np.percentile(x, [10, 50, 90])) if x.size else "-"


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    path = sys.argv[1]
    profile, dtype, scale = from_tga_slices(path) if os.path.isdir(path) else from_vdb(path)
    occ = profile > 0
    surf = occ & (profile < 0.5)
    n = int(occ.sum())
    if n == 0:
        sys.exit(f"{path}: no occupied voxel")
    print(f"{path}")
    print(f"  occupied voxels {n}, surface (profile < 0.5) {100.0 * surf.sum() / n:.0f}%")
    print(f"  profile p50 / p90            {np.percentile(profile[occ], 50):.2f} / {np.percentile(profile[occ], 90):.2f}")
    print(f"  detail type   surface        {pct(dtype[surf])}   occupied {pct(dtype[occ])}")
    print(f"  density scale surface        {pct(scale[surf])}   occupied {pct(scale[occ])}")


if __name__ == "__main__":
    main()

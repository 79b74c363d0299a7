#!/usr/bin/python3
"""Uniform calibration shapes as NVDF VDB sets for atlas preview (docs/render.md, "Calibration").

    /usr/bin/python3 scripts/calibration_shapes.py OUT_DIR [--size METRES] [--res N]

Writes OUT_DIR/box.vdb and OUT_DIR/sphere.vdb: grids dimensional_profile = 1, detail_type = 0,
density_scale = 1 inside the shape (density 1 for Atlas's sampler: (1 x 1)^0.6), sdf = signed
distance in metres (negative inside), on an N^3 grid spanning a cube of SIZE metres plus a
two-voxel margin. The optical thickness is set at render time by --extinction (tau = extinction
x SIZE across the shape).
"""
import os
import sys

import numpy as np
import pyopenvdb as vdb


def write(path, sdf, voxel, origin):
    inside = (sdf < 0).astype(np.float32)
    grids = []
    for name, arr in (("dimensional_profile", inside), ("detail_type", np.zeros_like(inside)), ("density_scale", inside), ("sdf", sdf.astype(np.float32))):
        g = vdb.FloatGrid(background=0.0 if name != "sdf" else float(sdf.max()))
        # numpy [x, y, z] -> VDB (i, j, k)
        g.copyFromArray(np.ascontiguousarray(arr), tolerance=0)
        g.name = name
        g.transform = vdb.createLinearTransform(voxelSize=voxel)
        g.transform.translate((origin + 0.5 * voxel,) * 3)
        grids.append(g)
    vdb.write(path, grids=grids)


def main(argv):
    args = [a for a in argv[1:] if not a.startswith("--")]
    if len(args) != 1:
        raise SystemExit(__doc__)
    size = float(argv[argv.index("--size") + 1]) if "--size" in argv else 1000.0
    res = int(argv[argv.index("--res") + 1]) if "--res" in argv else 40
    out = args[0]
    os.makedirs(out, exist_ok=True)
    margin = 2
    voxel = size / (res - 2 * margin)
    origin = -0.5 * size - margin * voxel
    c = origin + (np.arange(res) + 0.5) * voxel
    x, y, zc = np.meshgrid(c, c, c, indexing="ij")  # centred on the origin
    h = 0.5 * size
    q = np.stack([np.abs(x) - h, np.abs(y) - h, np.abs(zc) - h])
    box = np.linalg.norm(np.maximum(q, 0), axis=0) + np.minimum(q.max(axis=0), 0)
    sphere = np.sqrt(x * x + y * y + zc * zc) - h
    write(os.path.join(out, "box.vdb"), box, voxel, origin)
    write(os.path.join(out, "sphere.vdb"), sphere, voxel, origin)
    print(f"wrote box.vdb, sphere.vdb ({res}^3, voxel {voxel:.4g} m) to {out}")


if __name__ == "__main__":
    main(sys.argv)

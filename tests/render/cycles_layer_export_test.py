#!/usr/bin/python3
"""The 2.5D scene export (atlas preview GRAPH --export-scene DIR on a layer preview; docs/render.md,
"2.5D against Cycles") checked without Blender: the preview's own transmittance (its curved-Earth
march of the full layer density) against an independent march through the exported density.vdb
(read by pyopenvdb, trilinear, camera rebuilt from scene.json), pixel by pixel. The same march
through the grid moved by 600 m must fail the bound (the check can fail).

    cycles_layer_export_test.py --atlas BIN --graph GRAPH --work DIR
"""
import argparse
import json
import os
import subprocess
import sys

import numpy as np
import pyopenvdb as vdb

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "scripts"))
import render_compare as rc  # noqa: E402


def trilinear(grid, u):
    """grid [x, y, z]; u continuous voxel coordinates (centres at i + 0.5), zero outside."""
    u = u - 0.5
    i0 = np.floor(u).astype(int)
    t = u - i0
    out = np.zeros(len(u))
    n = np.array(grid.shape)
    for dx in (0, 1):
        for dy in (0, 1):
            for dz in (0, 1):
                i = i0 + np.array([dx, dy, dz])
                w = np.prod(np.where(np.array([dx, dy, dz]) == 1, t, 1 - t), axis=1)
                ok = np.all((i >= 0) & (i < n), axis=1)
                v = np.zeros(len(u))
                v[ok] = grid[i[ok, 0], i[ok, 1], i[ok, 2]]
                out += w * v
    return out


def march_transmittance(sc, grid, shift, px):
    c = sc["camera"]
    pos, look, up = (np.array(c[k], dtype=float) for k in ("position", "look_at", "up"))
    fwd = (look - pos) / np.linalg.norm(look - pos)
    right = np.cross(fwd, up)
    right /= np.linalg.norm(right)
    upv = np.cross(right, fwd)
    w, h = sc["width"], sc["height"]
    hh = np.tan(0.5 * np.radians(c["fov_y_deg"]))
    hw = hh * w / h
    lo = np.array(sc["bounds_min"]) + shift
    hi = np.array(sc["bounds_max"]) + shift
    vox = (hi - lo) / np.array(sc["resolution"])
    out = []
    for (x, y) in px:
        d = fwd + right * ((2 * (x + 0.5) / w - 1) * hw) + upv * ((2 * (y + 0.5) / h - 1) * hh)
        d /= np.linalg.norm(d)
        with np.errstate(divide="ignore", invalid="ignore"):
            ta, tb = (lo - pos) / d, (hi - pos) / d
        t0 = max(np.nanmax(np.minimum(ta, tb)), 0.0)
        t1 = np.nanmin(np.maximum(ta, tb))
        if not t1 > t0:
            out.append(1.0)
            continue
        step = 0.25 * vox.min()
        ts = np.arange(t0 + 0.5 * step, t1, step)
        p = pos + ts[:, None] * d
        dens = trilinear(grid, (p - lo) / vox)
        out.append(float(np.exp(-sc["extinction_per_metre"] * dens.sum() * step)))
    return np.array(out)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--atlas", required=True)
    ap.add_argument("--graph", required=True)
    ap.add_argument("--work", required=True)
    a = ap.parse_args()
    os.makedirs(a.work, exist_ok=True)
    scene_dir = os.path.join(a.work, "scene")
    img = os.path.join(a.work, "atlas.exr")
    subprocess.run([a.atlas, "preview", a.graph, "--artistic", "off", "--view", "orbit:30,25", "--fov", "20", "--size", "48x27",
                    "--cache", os.path.join(a.work, "cache"), "--export-scene", scene_dir, "-o", img], check=True,
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    sc = json.load(open(os.path.join(scene_dir, "scene.json")))
    assert sc["layer"]["boundary_max_density"] == 0, sc["layer"]
    g = vdb.read(os.path.join(scene_dir, "density.vdb"), sc["density_grid"])
    assert np.allclose(g.transform.indexToWorld((0, 0, 0)), np.array(sc["bounds_min"]) + 0.5 * (np.array(sc["bounds_max"]) - sc["bounds_min"]) / sc["resolution"], atol=1e-3)
    grid = np.zeros(sc["resolution"], dtype=np.float32)
    g.copyToArray(grid, ijk=(0, 0, 0))
    # The preview's transmittance; EXR row 0 is the top, the renderer's y = 0 the bottom.
    t_atlas = rc.channels(img)["transmittance"][::-1]
    h, w = t_atlas.shape
    ys, xs = np.nonzero(t_atlas < 0.98)
    rng = np.random.default_rng(1)
    pick = rng.choice(len(xs), size=min(60, len(xs)), replace=False)
    px = [(int(xs[i]), int(ys[i])) for i in pick]
    # some clear pixels too
    cy, cx = np.nonzero(t_atlas >= 0.999)
    px += [(int(cx[i]), int(cy[i])) for i in rng.choice(len(cx), size=min(20, len(cx)), replace=False)]
    ta = np.array([t_atlas[y, x] for x, y in px])
    good = np.abs(march_transmittance(sc, grid, np.zeros(3), px) - ta)
    bad = np.abs(march_transmittance(sc, grid, np.array([600.0, 0.0, 0.0]), px) - ta)
    print(f"{len(px)} pixels ({len(pick)} cloudy): mean |dT| {good.mean():.4f} (max {good.max():.4f}); grid moved 600 m: {bad.mean():.4f}")
    bound = 0.04
    ok = good.mean() < bound and bad.mean() > bound
    if not ok:
        print(f"FAIL: bound {bound}")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())

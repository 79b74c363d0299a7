#!/usr/bin/python3
"""Brute-force reference for the preview's diffusion term: analog Monte Carlo through a union of
disjoint axis-aligned boxes of one extinction (isotropic phase, albedo 1, no absorption), every
scattering order (docs/render.md, "Against brute force").

    /usr/bin/python3 scripts/box_mc.py CASE.json [--paths N] [--seed S]

CASE.json: {"boxes": [[[x0, y0, z0], [x1, y1, z1]], ...], "extinction": per metre,
            "views": [{"name": ..., "target": [x, y, z], "dir": [dx, dy, dz]}, ...],
            "sun": [toward the sun] (optional)}
Per view, the radiance toward a camera looking along dir at target (a point on a box's surface; the
ray starts 3 km back) in the preview's units: the sun's share per unit sun colour (E / 4 pi; next-event
estimation with the box chords' exact transmittance at every scattering) and the sky's share for the
basis L(w) = max(0, w . up) (a path that leaves the boxes takes L of its direction; the uniform sky's
share is exactly 1, the furnace). Prints one JSON line per view with both means and standard errors.
"""
import json
import sys

import numpy as np


def ray_boxes(p, w, lo, hi):
    """Per ray (rows of p, w) and box: the entry and exit distances (inf / -inf when missed)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1.0 / w
        t1 = (lo[None] - p[:, None]) * inv[:, None]
        t2 = (hi[None] - p[:, None]) * inv[:, None]
    tmin = np.nan_to_num(np.minimum(t1, t2), nan=-np.inf).max(axis=2)
    tmax = np.nan_to_num(np.maximum(t1, t2), nan=np.inf).min(axis=2)
    return tmin, tmax


def optical_depth(p, d, lo, hi, sigma):
    """Optical depth from each point of p along the one direction d (the boxes' chords summed)."""
    tmin, tmax = ray_boxes(p, np.tile(d, (len(p), 1)), lo, hi)
    return sigma * np.clip(tmax - np.maximum(tmin, 0), 0, None).sum(axis=1)


def radiance(boxes, sigma, target, direction, sun=None, paths=40000, seed=1):
    rng = np.random.default_rng(seed)
    lo = np.array([b[0] for b in boxes], float)
    hi = np.array([b[1] for b in boxes], float)
    d = np.asarray(direction, float) / np.linalg.norm(direction)
    p = np.tile(np.asarray(target, float) - d * 3000, (paths, 1))
    w = np.tile(d, (paths, 1))
    inside = np.zeros(paths, bool)
    alive = np.ones(paths, bool)
    sun_acc, sky_acc = np.zeros(paths), np.zeros(paths)
    s_dir = None if sun is None else np.asarray(sun, float) / np.linalg.norm(sun)
    while alive.any():
        idx = np.nonzero(alive)[0]
        tmin, tmax = ray_boxes(p[idx], w[idx], lo, hi)
        ins = inside[idx]
        # Outside: on to the next box the ray meets, or away (the sky basis of its direction).
        # (tmin > tmax: the ray's line misses that box; with one box an exiting path never sees
        # that with tmax > 0, with two it can, and it jumped into empty space "inside")
        ahead = np.where((tmax > 1e-9) & (tmin <= tmax), np.maximum(tmin, 0), np.inf)
        t_hit = ahead.min(axis=1)
        gone = ~ins & ~np.isfinite(t_hit)
        sky_acc[idx[gone]] = np.maximum(0, w[idx[gone], 2])
        alive[idx[gone]] = False
        hit = ~ins & np.isfinite(t_hit)
        h = idx[hit]
        p[h] += w[h] * (t_hit[hit, None] + 1e-6)
        inside[h] = True
        # Inside: a free flight; past the box's exit the path is outside again (memoryless).
        if ins.any():
            i = idx[ins]
            texit = np.where((tmin[ins] <= 1e-9) & (tmax[ins] > 0), tmax[ins], np.inf).min(axis=1)
            s = -np.log1p(-rng.random(i.size)) / sigma
            leave = s >= texit
            p[i[leave]] += w[i[leave]] * (texit[leave, None] + 1e-6)
            inside[i[leave]] = False
            sc = i[~leave]
            p[sc] += w[sc] * s[~leave, None]
            if s_dir is not None:
                sun_acc[sc] += np.exp(-optical_depth(p[sc], s_dir, lo, hi, sigma))
            u = 2 * rng.random(sc.size) - 1
            ph = 2 * np.pi * rng.random(sc.size)
            r = np.sqrt(1 - u * u)
            w[sc] = np.stack([r * np.cos(ph), r * np.sin(ph), u], axis=1)
    n = np.sqrt(paths)
    return {"sun": float(sun_acc.mean()), "sun_se": float(sun_acc.std() / n), "sky_basis": float(sky_acc.mean()), "sky_basis_se": float(sky_acc.std() / n)}


def main(argv):
    if len(argv) < 2:
        raise SystemExit(__doc__)
    case = json.load(open(argv[1]))
    opts = {"paths": 40000, "seed": 1}
    for k, v in zip(argv[2::2], argv[3::2]):
        if k not in ("--paths", "--seed"):
            raise SystemExit(f"unknown option {k}")
        opts[k[2:]] = int(v)
    for v in case["views"]:
        r = radiance(case["boxes"], case["extinction"], v["target"], v["dir"], case.get("sun"), opts["paths"], opts["seed"])
        print(json.dumps({"view": v["name"], **r}))


if __name__ == "__main__":
    main(sys.argv)

"""Issue 41: the shipped towering cumulus has the anatomy of a cumulus, read back with
OpenVDB's own Python reader (pyopenvdb), nothing of Atlas's: a flat base (the cloud's
columns start within a voxel or two of one height), towers (the top well above the
bulk), lobes at several scales (more bumps on the top surface than the same spheres without billows),
billowy detail type on the tops and wispy undersides, density scale rising from the
base, and the pack's soft shell at its low density scale. The same anatomy on graphs/cumulus_cloudscape.yaml's solver-grown towers, as the
ctest fixture `cook_shipped_cumulus_cloudscape` cooked them (the 32^3 quick tower; its NVDF set
is ATLAS_SHIPPED_CUMULUS_CLOUDSCAPE). Run by ctest (test `look_cumulus_anatomy`) with ATLAS_BIN
set."""
import os
import pathlib
import subprocess

import numpy as np
import pyopenvdb as vdb
import pytest

SOURCE = pathlib.Path(os.environ.get("ATLAS_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))
VOXEL = 8.0
RES = (128, 128, 96)
BASE = 170.0


def cook_towering(out, *sets):
    args = [os.environ["ATLAS_BIN"], "cook", str(SOURCE / "graphs" / "towering_cumulus.yaml"), "--out", str(out),
            "--no-cache", "--quiet", "--output", "towering_cumulus.vdb"]
    for s in sets:
        args += ["--set", s]
    subprocess.run(args, check=True)
    found = {g.name: g for g in vdb.readAll(str(out / "towering_cumulus.vdb"))[0]}
    arrays = {}
    for name in ("dimensional_profile", "detail_type", "density_scale", "sdf"):
        g = found[name]
        a = np.zeros(RES, dtype=np.float32)
        a.fill(g.background)
        g.copyToArray(a, ijk=(0, 0, 0))  # index space: the grid's origin voxel is (0, 0, 0)
        arrays[name] = a
    return arrays


@pytest.fixture(scope="module")
def grids(tmp_path_factory):
    return cook_towering(tmp_path_factory.mktemp("towering"))


def test_flat_base_at_the_condensation_height(grids):
    occ = grids["dimensional_profile"] > 0.05
    cols = occ.any(axis=2)
    assert cols.sum() > 500, "a cloud, not a speck"
    base = np.argmax(occ, axis=2)[cols] * VOXEL  # lowest occupied voxel of each column (its lower face)
    # The cloud sits on one plane: most columns start within two voxels of the lowest.
    lowest = base.min()
    assert abs(lowest - BASE) <= 2 * VOXEL, (lowest, BASE)
    assert np.mean(base <= lowest + 2 * VOXEL) > 0.6, np.percentile(base, [10, 50, 90])


def test_towers_rise_above_the_bulk(grids):
    occ = grids["dimensional_profile"] > 0.05
    cols = occ.any(axis=2)
    top = (occ.shape[2] - 1 - np.argmax(occ[:, :, ::-1], axis=2))[cols] * VOXEL
    assert top.max() - np.median(top) > 100, (top.max(), np.median(top))


def top_peaks(grids):
    """Distinct bumps of the top surface: 5x5-column (40 m) local maxima inside the footprint."""
    occ = grids["dimensional_profile"] > 0.05
    cols = occ.any(axis=2)
    top = np.where(cols, occ.shape[2] - 1 - np.argmax(occ[:, :, ::-1], axis=2), 0).astype(float) * VOXEL
    k = 2
    pad = np.pad(top, k, mode="edge")
    local_max = np.zeros_like(top)
    inner = cols.copy()
    for dx in range(-k, k + 1):
        for dy in range(-k, k + 1):
            local_max = np.maximum(local_max, pad[k + dx:k + dx + top.shape[0], k + dy:k + dy + top.shape[1]])
            inner &= np.roll(np.roll(cols, dx, 0), dy, 1)
    peak = (top == local_max) & inner
    # One bump per 8-connected plateau of peak columns.
    seen = np.zeros_like(peak)
    count = 0
    for start in zip(*np.nonzero(peak)):
        if seen[start]:
            continue
        count += 1
        stack = [start]
        seen[start] = True
        while stack:
            x, y = stack.pop()
            for dx in (-1, 0, 1):
                for dy in (-1, 0, 1):
                    q = (x + dx, y + dy)
                    if 0 <= q[0] < peak.shape[0] and 0 <= q[1] < peak.shape[1] and peak[q] and not seen[q]:
                        seen[q] = True
                        stack.append(q)
    return count


def test_lobes_on_lobes(grids, tmp_path_factory):
    # Against the same spheres without billows (levels 0): measured 30 bumps
    # with them, 20 without. (A rough top alone no longer tells them apart:
    # the graph's smaller spheres are rough at 40 m by themselves, 8.6 m
    # against 9.3 m with billows.)
    bare = cook_towering(tmp_path_factory.mktemp("bare"), "shape.levels=0")
    n, n0 = top_peaks(grids), top_peaks(bare)
    assert n0 >= 5, "the bare spheres have their own tops"
    assert n >= 1.3 * n0, (n, n0)


def test_billowy_tops_wispy_undersides_density_from_the_base(grids):
    dp, dt, ds = grids["dimensional_profile"], grids["detail_type"], grids["density_scale"]
    occ = dp > 0.05
    cols = occ.any(axis=2)
    topz = occ.shape[2] - 1 - np.argmax(occ[:, :, ::-1], axis=2)
    basez = np.argmax(occ, axis=2)
    xs, ys = np.nonzero(cols)
    tops = dt[xs, ys, topz[xs, ys]]
    bases = dt[xs, ys, basez[xs, ys]]
    assert np.mean(tops) > 0.6, np.mean(tops)
    assert np.mean(bases) < 0.2, np.mean(bases)
    base_scale = ds[xs, ys, basez[xs, ys]]
    high = ds[:, :, int((BASE + 200) / VOXEL)][occ[:, :, int((BASE + 200) / VOXEL)]]
    assert high.size > 0 and np.mean(high) > np.mean(base_scale) + 0.2



def test_a_soft_shell_at_the_packs_density_scale(grids):
    # Issue 41 item 8: Guerrilla's two pack clouds, measured with scripts/nvdf_stats.py
    # (docs/look.md), are 79-86% shell (0 < profile < 0.5) with a median density scale of
    # 0.24-0.31 over the occupied voxels. The old graph was 23% shell at scale 1.0 and
    # rendered grey and solid beside them; now 57% at 0.31.
    dp, ds = grids["dimensional_profile"], grids["density_scale"]
    occ = dp > 0
    shell = occ & (dp < 0.5)
    assert shell.sum() / occ.sum() > 0.45, shell.sum() / occ.sum()
    assert 0.15 < np.median(ds[occ]) < 0.45, np.median(ds[occ])

# graphs/cumulus_cloudscape.yaml: 256 x 256 x 224 voxels over 4 x 4 x 3.5 km, base 650 m.
CS_RES = (256, 256, 224)
CS_VOXEL = 4000.0 / 256
CS_BASE = 650.0


@pytest.fixture(scope="module")
def cloudscape():
    g = {g.name: g for g in vdb.readAll(os.environ["ATLAS_SHIPPED_CUMULUS_CLOUDSCAPE"])[0]}["dimensional_profile"]
    a = np.zeros(CS_RES, dtype=np.float32)
    g.copyToArray(a, ijk=(0, 0, 0))
    return a > 0.05


def test_grown_towers_stand_on_a_flat_base(cloudscape):
    occ = cloudscape
    cols = occ.any(axis=2)
    assert cols.sum() > 2000, "clouds, not specks"
    base = np.argmax(occ, axis=2)[cols] * CS_VOXEL
    # Nothing below the condensation height; the bulk of the columns start on it (the
    # rest are lobes bulging out over the base and the decaying tower's bubbles).
    assert CS_BASE - CS_VOXEL <= base.min() <= CS_BASE + 2 * CS_VOXEL, base.min()
    assert np.mean(base <= base.min() + 2 * CS_VOXEL) > 0.3, np.percentile(base, [10, 50, 90])


def test_the_grown_cloud_is_a_tower(cloudscape):
    # The tower as grown (south-west quarter): taller than it is wide. Measured on the
    # 32^3 quick tower: 2.44 km tall on a 1.39 km footprint (1.75); the soft blob this
    # graph made before was about as tall as wide.
    occ = cloudscape[:128, :128, :]
    cols = occ.any(axis=2)
    xs, ys = np.nonzero(cols)
    width = max(xs.max() - xs.min(), ys.max() - ys.min()) * CS_VOXEL
    top = (occ.shape[2] - 1 - np.argmax(occ[:, :, ::-1], axis=2))[cols].max() * CS_VOXEL
    height = top - np.argmax(occ, axis=2)[cols].min() * CS_VOXEL
    assert height > 1.2 * width, (height, width)

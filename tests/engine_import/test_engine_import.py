"""Engine import: an NVDF set cooked by Atlas, read the way an engine's importer would.

Readers here are other people's: OpenImageIO (DDS, TGA) and OpenVDB's own Python module
(pyopenvdb). Nothing of Atlas's is used to read. The three files must agree voxel for voxel in
world space: the TGA slice stack and the DDS volume texture (8-bit, the same quantisation) must
hold identical bytes at the same world position, and the VDB floats must round to them.

Run by ctest (test `engine_import`) with ATLAS_BIN set to the atlas program.
"""
import os
import pathlib
import struct
import subprocess

import numpy as np
import OpenImageIO as oiio
import pyopenvdb as vdb
import pytest

NX, NY, NZ = 24, 16, 8
BMIN = (-1000.0, 2000.0, 100.0)
BMAX = (2000.0, 4000.0, 612.0)
VOX = tuple((BMAX[i] - BMIN[i]) / n for i, n in enumerate((NX, NY, NZ)))

GRAPH = f"""atlas: 1
nodes:
  base:
    type: noise/value
    params: {{resolution: [{NX}, {NY}, {NZ}], bounds_min: [{BMIN[0]}, {BMIN[1]}, {BMIN[2]}],
             bounds_max: [{BMAX[0]}, {BMAX[1]}, {BMAX[2]}], period: [3, 2, 1], octaves: 3, seed: 11}}
  coverage:
    type: math/remap
    inputs: {{in: base}}
    params: {{in_min: 0.4, in_max: 0.7, clamp: true}}
  distance:
    type: volume/sdf
    inputs: {{in: coverage}}
  nvdf:
    type: volume/nvdf
    inputs: {{sdf: distance}}
    params: {{depth: 200}}
outputs:
  - {{node: nvdf, port: modeling, file: pack/modeling, format: tga-slices, options: {{alpha: 0}}}}
  - {{node: nvdf, port: modeling, file: modeling.dds, options: {{encoding: rgba8, range: "0,1"}}}}
  - {{node: nvdf, port: vdb_set, file: set.vdb}}
"""

CHANNELS = ["dimensional_profile", "detail_type", "density_scale"]


@pytest.fixture(scope="module")
def cooked(tmp_path_factory):
    atlas = os.environ.get("ATLAS_BIN", "build/bin/atlas")
    d = tmp_path_factory.mktemp("engine_import")
    g = d / "set.yaml"
    g.write_text(GRAPH)
    subprocess.run([atlas, "cook", str(g), "--out", str(d / "out"), "--no-cache", "--quiet"], check=True)
    return d / "out"


def world_centre(x, y, z):
    return tuple(BMIN[i] + (c + 0.5) * VOX[i] for i, c in enumerate((x, y, z)))


def read_tga_stack(out):
    """[z, y, x, c] uint8, y counted from the bottom of the world (the pack's convention)."""
    files = sorted((out / "pack").glob("modeling.*.tga"))
    assert len(files) == NZ, files
    slices = []
    for f in files:
        # The pack's alpha is 0: ask for the stored colour bytes, not OIIO's premultiplied ones.
        config = oiio.ImageSpec()
        config.attribute("oiio:UnassociatedAlpha", 1)
        inp = oiio.ImageInput.open(str(f), config)
        assert inp, oiio.geterror()
        spec = inp.spec()
        assert (spec.width, spec.height, spec.nchannels) == (NX, NY, 4)
        px = inp.read_image(0, 0, 0, 4, oiio.UINT8)  # rows top-down, as displayed
        inp.close()
        slices.append(px[::-1])  # bottom row first = y up
    return np.stack(slices)


def read_dds_volume(out):
    """[z, y, x, c] uint8 from the DDS, y up. OpenImageIO 2.4 reads 2D DDS only, so a volume
    texture is parsed here from the DDS specification (DX10 header, R8G8B8A8_UNORM, depth
    slices one after another, rows top-down), and each slice is cross-checked against
    OpenImageIO where it can read the file."""
    b = (out / "modeling.dds").read_bytes()
    assert b[:4] == b"DDS "
    height, width, pitch, depth, mips = struct.unpack_from("<5I", b, 12)
    assert (width, height, depth) == (NX, NY, NZ)
    assert b[84:88] == b"DX10"
    dxgi, dim = struct.unpack_from("<2I", b, 128)
    assert dxgi == 28, f"expected R8G8B8A8_UNORM (28), got {dxgi}"
    assert dim == 4, "expected a TEXTURE3D"
    data = np.frombuffer(b, dtype=np.uint8, offset=148, count=NX * NY * NZ * 4)
    vol = data.reshape(NZ, NY, NX, 4)  # rows as stored: top first
    return vol[:, ::-1]


def read_vdb(out):
    grids = {g.name: g for g in vdb.readAll(str(out / "set.vdb"))[0]}
    for name in CHANNELS + ["sdf"]:
        assert name in grids, f"{name} missing from {sorted(grids)}"
    return grids


def test_tga_and_dds_agree_byte_for_byte(cooked):
    tga = read_tga_stack(cooked)
    dds = read_dds_volume(cooked)
    assert np.array_equal(tga[..., :3], dds[..., :3]), "TGA slices and DDS disagree"
    # Not a constant field: the comparison has something to compare.
    assert tga[..., 0].min() < 64 and tga[..., 0].max() > 192


def test_vdb_agrees_with_tga_in_world_space(cooked):
    tga = read_tga_stack(cooked)
    grids = read_vdb(cooked)
    worst = 0.0
    for c, name in enumerate(CHANNELS):
        g = grids[name]
        acc = g.getConstAccessor()
        xf = g.transform
        for z in range(NZ):
            for y in range(NY):
                for x in range(NX):
                    ijk = xf.worldToIndex(world_centre(x, y, z))
                    idx = tuple(int(round(v)) for v in ijk)
                    assert max(abs(a - b) for a, b in zip(ijk, idx)) < 1e-6, "voxel centres are not on the index grid"
                    v = acc.getValue(idx)
                    worst = max(worst, abs(v * 255.0 - float(tga[z, y, x, c])))
    assert worst <= 0.5 + 1e-3, f"VDB and TGA differ by {worst} of 255 steps"


def test_vdb_sdf_sign_matches_dimensional_profile(cooked):
    """Inside (sdf < 0) is where the dimensional profile is positive: the same voxel in both."""
    tga = read_tga_stack(cooked)
    g = read_vdb(cooked)["sdf"]
    acc = g.getConstAccessor()
    inside = 0
    for z in range(NZ):
        for y in range(NY):
            for x in range(NX):
                idx = tuple(int(round(v)) for v in g.transform.worldToIndex(world_centre(x, y, z)))
                d = acc.getValue(idx)
                if tga[z, y, x, 0] > 0:
                    assert d < 0, f"profile > 0 but sdf {d} at {(x, y, z)}"
                    inside += 1
    assert inside > 0


def test_flipped_reading_would_fail(cooked):
    """The comparison can fail: reading the DDS rows bottom-up gives a different volume."""
    tga = read_tga_stack(cooked)
    dds = read_dds_volume(cooked)
    assert not np.array_equal(tga[..., :3], dds[:, ::-1, :, :3])


def test_oiio_reads_a_2d_dds_like_the_png(cooked, tmp_path):
    """A 2D field written as BC4 DDS and as PNG by the same graph: OpenImageIO shows the same
    picture (OIIO 2.4 reads 2D BC1/BC4 DDS files, not DX10 uncompressed ones or volumes)."""
    atlas = os.environ.get("ATLAS_BIN", "build/bin/atlas")
    g = tmp_path / "slice.yaml"
    g.write_text(f"""atlas: 1
nodes:
  base:
    type: noise/value
    params: {{resolution: [32, 16, 1], period: [4, 2, 1], octaves: 2, seed: 5}}
outputs:
  - {{node: base, file: s.png}}
  - {{node: base, file: s.dds, options: {{encoding: bc4, range: "0,1", max_error: 0.04}}}}
""")
    subprocess.run([atlas, "cook", str(g), "--out", str(tmp_path / "o"), "--no-cache", "--quiet"], check=True)
    png = oiio.ImageBuf(str(tmp_path / "o" / "s.png"))
    dds = oiio.ImageBuf(str(tmp_path / "o" / "s.dds"))
    a = png.get_pixels(oiio.FLOAT)[..., 0]
    b = dds.get_pixels(oiio.FLOAT)[..., 0]
    assert a.shape == b.shape
    assert np.max(np.abs(a - b)) <= 0.04 + 1.5 / 255  # BC4's bound plus the PNG's and OIIO's 8-bit rounding
    assert np.max(np.abs(a - b[::-1])) > 0.05

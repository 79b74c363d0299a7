#!/usr/bin/env python3
"""ctest preview_animation: `atlas preview --turntable/--frames` also as one animated WebP and one
contact sheet (docs/render.md, "Sequences"), read back by programs that are not Atlas's: Pillow
decodes the animation (composited frames, durations, loop), webpmux lists its frames, OpenImageIO
reads the PNG frames and the sheet. Then a graph with a time range (docs/graph-format.md, "Time"):
`atlas cook --frames` and the preview's frames of graphs/superstorm_lifecycle.yaml.

    ATLAS=build/bin/atlas ATLAS_SOURCE_DIR=. python3 tests/render/animation_test.py
"""
import os
import subprocess
import sys
import tempfile

import numpy as np
import OpenImageIO as oiio
from PIL import Image

ATLAS = os.environ["ATLAS"]
SRC = os.environ["ATLAS_SOURCE_DIR"]
GRAPH = os.path.join(SRC, "graphs", "towering_cumulus.yaml")
failures = []


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what)
    if not ok:
        failures.append(what)


def atlas(*args, expect=0):
    r = subprocess.run([ATLAS, "preview", GRAPH, "--size", "96x54", "--quiet", *args], capture_output=True, text=True)
    check(r.returncode == expect, f"exit {r.returncode} (expected {expect}) for {' '.join(args)}: {r.stderr.strip()[:300]}")
    return r


def png(path):
    return oiio.ImageInput.open(path).read_image("uint8")[..., :3].astype(int)


def frames_of(webp):
    im = Image.open(webp)
    out, durations = [], []
    for i in range(im.n_frames):
        im.seek(i)
        out.append(np.asarray(im.convert("RGB")).astype(int))
        durations.append(im.info.get("duration"))
    return out, durations, im.info.get("loop")


with tempfile.TemporaryDirectory() as d:
    cache = ["--cache", os.path.join(d, "cache")]
    # Lossless: the animation holds exactly the PNG frames' pixels.
    out = os.path.join(d, "t.png")
    atlas("--turntable", "4", "-o", out, "--animation", os.path.join(d, "t.webp"), "--animation-quality", "101", "--fps", "8",
          "--contact-sheet", os.path.join(d, "sheet.png"), *cache)
    frames = [png(os.path.join(d, f"t_{i:03d}.png")) for i in range(4)]
    anim, durations, loop = frames_of(os.path.join(d, "t.webp"))
    check(len(anim) == 4, f"4 frames in the animation (Pillow): {len(anim)}")
    check(all(a.shape == (54, 96, 3) for a in anim), "every frame 96x54")
    check(all(np.array_equal(a, f) for a, f in zip(anim, frames)), "lossless frames equal the PNG frames")
    check(not np.array_equal(frames[0], frames[1]), "the turntable turns (frames differ)")
    check(all(abs(t - 125) <= 1 for t in durations), f"8 fps: 125 ms a frame, got {durations}")
    check(loop == 0, f"loops forever (loop 0), got {loop}")
    info = subprocess.run(["webpmux", "-info", os.path.join(d, "t.webp")], capture_output=True, text=True).stdout
    check("Number of frames: 4" in info and "Canvas size: 96 x 54" in info, "webpmux: 4 frames on a 96 x 54 canvas")
    # The sheet: 2 x 2 tiles, 4 pixels apart, frame 0 top left, each the PNG frame.
    sheet = png(os.path.join(d, "sheet.png"))
    check(sheet.shape == (2 * 54 + 4, 2 * 96 + 4, 3), f"sheet size {sheet.shape}")
    for i in range(4):
        r, c = divmod(i, 2)
        tile = sheet[r * 58:r * 58 + 54, c * 100:c * 100 + 96]
        check(np.array_equal(tile, frames[i]), f"sheet tile {i} is frame {i}")
    check(sheet[:, 96:100].max() == 0, "black between the tiles")

    # Lossy (the default): close to the frames, smaller than lossless.
    atlas("--turntable", "4", "-o", os.path.join(d, "l.png"), "--animation", os.path.join(d, "l.webp"), *cache)
    lossy, _, _ = frames_of(os.path.join(d, "l.webp"))
    mse = np.mean([np.mean((a - f) ** 2) for a, f in zip(lossy, frames)])
    psnr = 10 * np.log10(255 ** 2 / max(mse, 1e-9))
    check(psnr > 30, f"lossy quality 90: PSNR {psnr:.1f} dB > 30 against the PNG frames")
    check(os.path.getsize(os.path.join(d, "l.webp")) < os.path.getsize(os.path.join(d, "t.webp")), "lossy is smaller than lossless")

    # A sheet in another folder is written there (atomically); frames of a time sequence too.
    other = os.path.join(d, "sheets")
    os.makedirs(other)
    atlas("--frames", "2", "-o", os.path.join(d, "s.png"), "--contact-sheet", os.path.join(other, "s_sheet.png"), *cache)
    check(os.path.exists(os.path.join(other, "s_sheet.png")) and os.path.exists(os.path.join(d, "s_001.png")), "sheet in another folder")

    # Bad input: a clear message, exit 2, nothing written.
    before = sorted(os.listdir(d))
    r = atlas("-o", os.path.join(d, "x.png"), "--animation", os.path.join(d, "x.webp"), expect=2)
    check("--animation needs --frames N or --turntable N" in r.stderr, f"--animation without frames: {r.stderr.strip()}")
    r = atlas("--turntable", "2", "-o", os.path.join(d, "x.png"), "--animation", os.path.join(d, "x.gif"), expect=2)
    check("name it .webp" in r.stderr, f"--animation x.gif: {r.stderr.strip()}")
    r = atlas("--turntable", "2", "-o", os.path.join(d, "x.png"), "--fps", "5", expect=2)
    check("--fps needs --animation" in r.stderr, f"--fps alone: {r.stderr.strip()}")
    r = atlas("--turntable", "2", "-o", os.path.join(d, "x.png"), "--animation", os.path.join(d, "x.webp"), "--fps", "0", expect=1)
    check("fps must be in (0, 120]" in r.stderr, f"--fps 0: {r.stderr.strip()}")
    check(sorted(os.listdir(d)) == before, "the refused previews wrote nothing")

# Time (docs/graph-format.md, "Time"): a graph's keyed parameters through its frames.
LIFE = os.path.join(SRC, "graphs", "superstorm_lifecycle.yaml")
with tempfile.TemporaryDirectory() as d:
    out = os.path.join(d, "frames")
    r = subprocess.run([ATLAS, "cook", LIFE, "--frames", "2:4", "--out", out, "--cache", os.path.join(d, "cache")], capture_output=True, text=True)
    check(r.returncode == 0, f"cook --frames 2:4: {r.stderr.strip()[-300:]}")
    import json
    m = json.load(open(os.path.join(out, "frames.json")))
    check([f["frame"] for f in m["frames"]] == [2, 3, 4] and [f["time"] for f in m["frames"]] == [40, 60, 80], f"frames and times {m['frames']!r:.200}")
    check(m["time"] == {"start": 0, "end": 480, "fps": 0.05, "frames": 25}, f"the time range {m['time']}")
    first, later = set(m["frames"][0]["cooked"]), [set(f["cooked"]) for f in m["frames"][1:]]
    check({"rings", "coverage_noise"} <= first, f"frame 2 cooks everything: {sorted(first)}")
    check(all(c == {"mesocyclone", "volume", "rings", "lightning"} for c in later),
          f"later frames re-cook only the keyed tower, its bake, the rings and the frame's lightning: {[sorted(c) for c in later]}")
    changes = {o["file"]: o["changes"] for o in m["outputs"]}
    check(changes.get("superstorm_ndf_set.exr") is True and changes.get("superstorm_anvil.exr") is False, f"which outputs change: {changes}")
    f3 = {o["file"]: o for o in m["frames"][1]["outputs"]}
    check(not f3["superstorm_anvil.exr"]["changed"] and f3["vortex_rings.json"]["changed"], "per frame: the anvil bias unchanged, the rings changed")
    # Before the tower tops out (40-80 s) there is no lightning: an unchanged table of none.
    check(not f3["lightning.json"]["changed"], "no lightning while the storm forms")
    # Per channel (what an engine re-uploads) and the world bounds.
    ch = {o["file"]: {c["name"]: c["changed"] for c in o["channels"]} for o in m["frames"][1]["outputs"]}
    check(ch["superstorm_anvil.exr"] == {"anvil_bias": False, "anvil_lift": False}, f"the anvil's channels unchanged: {ch['superstorm_anvil.exr']}")
    check(ch["superstorm_ndf_set.exr"]["coverage"] and not ch["superstorm_ndf_set.exr"]["precipitation"], f"the set's coverage changes, its rain does not: {ch['superstorm_ndf_set.exr']}")
    check(sorted(ch["superstorm_coverage_type_bottomtype.png"]) == ["bottom_type", "coverage", "type"], "a PNG lists the channels it holds")
    check(all(all(c["changed"] for c in o["channels"]) for o in m["frames"][0]["outputs"]), "in the first frame every channel counts as changed")
    check(f3["superstorm_ndf_set.exr"]["bounds"] == {"min": [0.0, 0.0], "max": [40000.0, 40000.0]}, f"the set's bounds: {f3['superstorm_ndf_set.exr'].get('bounds')}")
    check(all(os.path.exists(os.path.join(out, x["path"])) and os.path.getsize(os.path.join(out, x["path"])) == x["bytes"]
              for fr in m["frames"] for o in fr["outputs"] for x in o["files"]), "every listed file exists with its size")
    # The tower grows: its coverage sum rises from frame to frame (read with OpenImageIO).
    rings = [json.load(open(os.path.join(out, f["folder"], "vortex_rings.json"))) for f in m["frames"]]
    check(len({json.dumps(r, sort_keys=True) for r in rings}) == 3, "the rings' table follows the tower's radius")
    cov = []
    for f in m["frames"]:
        img = oiio.ImageInput.open(os.path.join(out, f["folder"], "superstorm_ndf_set.exr"))
        spec = img.spec()
        px = img.read_image("float")
        cov.append(float(px[..., spec.channelnames.index("superstorm_coverage")].sum()))
    check(cov[0] < cov[1] < cov[2], f"the storm forms: superstorm coverage {cov}")
    r = subprocess.run([ATLAS, "cook", LIFE, "--frames", "7:99", "--out", out], capture_output=True, text=True)
    check(r.returncode == 2 and "the graph's frames are 0:24" in r.stderr, f"a range past the end: {r.stderr.strip()}")
    r = subprocess.run([ATLAS, "cook", GRAPH, "--frames", "all", "--out", out], capture_output=True, text=True)
    check(r.returncode == 2 and "declares no time range" in r.stderr, f"a graph without time: {r.stderr.strip()}")
    # The preview steps the graph's time a frame (20 s) at a time: the storm grows on screen.
    atlas_life = subprocess.run([ATLAS, "preview", LIFE, "--frames", "3", "--time", "40", "--size", "96x54", "--quiet", "-o",
                                 os.path.join(d, "p.png"), "--cache", os.path.join(d, "cache")], capture_output=True, text=True)
    check(atlas_life.returncode == 0, f"preview --frames of a timed graph: {atlas_life.stderr.strip()[-300:]}")
    for args, what in ((["--time", "900"], "time runs from 0 to 480 s"), (["--frames", "30"], "runs past the graph's end at 480 s")):
        r = subprocess.run([ATLAS, "preview", LIFE, *args, "--size", "32x18", "--quiet", "-o", os.path.join(d, "bad.png")], capture_output=True, text=True)
        check(r.returncode == 2 and what in r.stderr, f"preview {' '.join(args)}: {r.stderr.strip()}")
    p = [png(os.path.join(d, f"p_{i:03d}.png")) for i in range(3)]
    check(not np.array_equal(p[0], p[1]) and not np.array_equal(p[1], p[2]), "the frames differ as the storm forms")

# Solver to sequence (issue 43 item 3): graphs/cumulus_sequence.yaml at its quick 32^3 grows once and
# writes an NVDF set (VDB, BC6H modeling, BC4 field data) per frame from the keyed solver frame.
SEQ = os.path.join(SRC, "graphs", "cumulus_sequence.yaml")
with tempfile.TemporaryDirectory() as d:
    out = os.path.join(d, "seq")
    quick = ["--set", "cloud.resolution=[32,32,32]", "--set", "cloud.dx=125"]
    r = subprocess.run([ATLAS, "cook", SEQ, "--frames", "6:8", "--out", out, "--no-cache", *quick], capture_output=True, text=True)
    check(r.returncode == 0, f"cook --frames 6:8 of the solver sequence: {r.stderr.strip()[-300:]}")
    m = json.load(open(os.path.join(out, "frames.json")))
    first, later = set(m["frames"][0]["cooked"]), [set(f["cooked"]) for f in m["frames"][1:]]
    check("cloud" in first, f"the first frame grows the cloud: {sorted(first)}")
    check(all(c == {"frame", "sdf", "nvdf"} for c in later), f"later frames re-cook the frame and its NVDF set only: {[sorted(c) for c in later]}")
    check(all(o["changed"] for f in m["frames"][1:] for o in f["outputs"]), "every output changes as the cloud grows")
    for f in m["frames"]:
        for name in ("cumulus_modeling.dds", "cumulus_field_data.dds", "cumulus_nvdf.vdb"):
            check(os.path.getsize(os.path.join(out, f["folder"], name)) > 0, f"{f['folder']}/{name} written")
    # The NVDF set's SDF read back with pyopenvdb (OpenVDB's own reader): the tower grows, more
    # voxels inside (sdf < 0) from frame to frame (8, 10, 20 at this size).
    import pyopenvdb
    inside = []
    for f in m["frames"]:
        g = pyopenvdb.read(os.path.join(out, f["folder"], "cumulus_nvdf.vdb"), "sdf")
        a = np.zeros((32, 32, 32), np.float32)
        g.copyToArray(a)
        inside.append(int((a < 0).sum()))
    check(0 < inside[0] < inside[1] < inside[2], f"voxels inside the cloud per frame: {inside}")

print(f"{len(failures)} failed" if failures else "all passed")
sys.exit(1 if failures else 0)

"""Issue 41 item 5: the renderer's accelerations never change the picture. For the default
view of every shipped graph that previews, rendered small: the 2.5D envelope (cone and
distance skipping) on against off and the voxel SDF skipping on against off must give the
same bytes (both walk the march's own steps over the space they skip); the voxel light grid
against marched light rays must stay within a mean absolute difference of 0.5/255 and a
99.9th percentile of 4/255. The pictures are read back with OpenImageIO, not with Atlas.
Run by ctest (test `look_accelerations`) with ATLAS_BIN set; the full-size numbers are
bench/accelerations.sh's."""
import os
import pathlib
import re
import subprocess

import numpy as np
import OpenImageIO as oiio
import pytest

SOURCE = pathlib.Path(os.environ.get("ATLAS_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))
SIZE = "128x72"

# Every shipped graph that `atlas preview` draws by itself (the cumulus_* graphs read a
# solver run's files, the noise graphs write no cloud), with what it draws.
LAYER = ["hzd_weather", "envelope_mountain", "fc6_forecast", "sky_layer", "superstorm"]
VOXEL = ["towering_cumulus", "cloudscape", "quickstart"]


def graph_path(name):
    return SOURCE / ("examples" if name == "quickstart" else "graphs") / (name + ".yaml")


@pytest.fixture(scope="module")
def cache(tmp_path_factory):
    return tmp_path_factory.mktemp("cache")


def render(tmp_path, cache, name, *extra, summary=None):
    out = tmp_path / (name + "_" + "_".join(e.strip("-").replace("/", "").replace(":", "") for e in extra) + ".png")
    run = subprocess.run([os.environ["ATLAS_BIN"], "preview", str(graph_path(name)), "-o", str(out), "--size", SIZE,
                          "--cache", str(cache), *extra], check=True, capture_output=True, text=True)
    if summary is not None:
        summary.append(run.stdout + run.stderr)
    return out


def skips(summary):
    m = re.search(r"(\d+) skips", summary)
    assert m, "no skip count in the preview summary:\n" + summary
    return int(m.group(1))


def pixels(path):
    buf = oiio.ImageBuf(str(path))
    assert not buf.has_error, buf.geterror()
    return buf.get_pixels(oiio.UINT8).astype(np.int32)


# Views where the envelope does skip (the test is not vacuous there): the others start under
# the clouds or draw 2D layers only. The superstorm's rings turn its noise, not its map, so the
# envelope skips while they turn.
SKIPPING = {("envelope_mountain", "default"), ("envelope_mountain", "aerial"), ("fc6_forecast", "default"), ("fc6_forecast", "aerial"),
            ("superstorm", "aerial")}


@pytest.mark.parametrize("view", ["default", "aerial"])
@pytest.mark.parametrize("name", LAYER)
def test_envelope_skipping_keeps_the_picture(tmp_path, cache, name, view):
    v = [] if view == "default" else ["--view", view]
    summary = []
    on = pixels(render(tmp_path, cache, name, "--envelope", "on", *v, summary=summary))
    off = pixels(render(tmp_path, cache, name, "--envelope", "off", *v))
    assert on.shape == off.shape
    assert np.array_equal(on, off), f"{name} {view}: envelope on vs off differ, mean {np.abs(on - off).mean():.3f}/255, max {np.abs(on - off).max()}"
    if name != "sky_layer":
        n = skips(summary[0])
        if (name, view) in SKIPPING:
            assert n > 0, f"{name} {view}: the envelope skipped nothing"


@pytest.mark.parametrize("name", VOXEL)
def test_sdf_skipping_keeps_the_picture(tmp_path, cache, name):
    on = pixels(render(tmp_path, cache, name))
    off = pixels(render(tmp_path, cache, name, "--sdf-skipping", "off"))
    assert np.array_equal(on, off), f"{name}: SDF skipping on vs off differ, max {np.abs(on - off).max()}"


@pytest.mark.parametrize("name", VOXEL)
def test_light_grid_stays_close_to_marched_light(tmp_path, cache, name):
    grid = pixels(render(tmp_path, cache, name))
    marched = pixels(render(tmp_path, cache, name, "--light-lookup", "marched"))
    d = np.abs(grid - marched)[..., :3]
    assert d.max() > 0 or name == "quickstart", f"{name}: the light grid and marched light gave the same bytes; is the option wired?"
    mean, p999 = d.mean(), np.percentile(d, 99.9)
    # The bound at the defaults (issue 41 item 5). Before the sheared sun map the
    # cloudscape's 128x128 light grid missed it (99.9th percentile 17/255 at 960x540).
    limit = 4
    assert mean <= 0.5, f"{name}: mean |grid - marched| {mean:.3f}/255 > 0.5"
    assert p999 <= limit, f"{name}: 99.9th percentile |grid - marched| {p999:.1f}/255 > {limit}"

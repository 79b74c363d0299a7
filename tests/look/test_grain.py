"""Issue 41 item 6: no grain at the default quality. Each 2.5D view of bench/grain.sh, rendered
small (160x90), against the same view with 16 times the steps (`--quality 16`): RMS at most
2/255 over the cloud region (scripts/grain_rms.py, read back with OpenImageIO). The superstorm's
ground view with six flashes is left out: it meets the bound at bench/grain.sh's 480x270 (1.97)
but not at this size (2.09: its wisps cover fewer pixels; docs/look.md). Run by ctest (test `look_grain`) with ATLAS_BIN set;
the 480x270 figures and the times are bench/grain.sh's."""
import os
import pathlib
import subprocess
import sys

import pytest

SOURCE = pathlib.Path(os.environ.get("ATLAS_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))
sys.path.insert(0, str(SOURCE / "scripts"))
from grain_rms import grain  # noqa: E402

SIZE = "160x90"
VIEWS = {
    "hzd_weather_ground": ("hzd_weather", []),
    "hzd_weather_aerial": ("hzd_weather", ["--view", "aerial"]),
    "fc6_forecast_ground": ("fc6_forecast", []),
    "envelope_mountain_aerial": ("envelope_mountain", ["--view", "aerial"]),
    "superstorm_37km": ("superstorm", ["--camera", "14000,-17000,2,14000,20000,5500", "--fov", "40"]),
}


@pytest.fixture(scope="module")
def cache(tmp_path_factory):
    return tmp_path_factory.mktemp("cache")


def render(out, cache, graph, extra, quality):
    subprocess.run([os.environ["ATLAS_BIN"], "preview", str(SOURCE / "graphs" / (graph + ".yaml")), "-o", str(out), "--size", SIZE,
                    "--cache", str(cache), "--quality", str(quality), "--quiet", *extra], check=True, capture_output=True, text=True)
    return out


@pytest.mark.parametrize("view", sorted(VIEWS))
def test_default_quality_is_within_2_of_16x_the_steps(tmp_path, cache, view):
    graph, extra = VIEWS[view]
    q1 = render(tmp_path / "q1.png", cache, graph, extra, 1)
    q16 = render(tmp_path / "q16.png", cache, graph, extra, 16)
    rms, region = grain(q1, q16)
    # Not vacuous: the view shows cloud, and the two pictures are not the same bytes.
    assert region > 5, f"{view}: cloud region only {region:.1f}% of the frame"
    assert rms > 0, f"{view}: quality 1 and 16 gave the same picture; is --quality wired?"
    assert rms <= 2.0, f"{view}: grain {rms:.2f}/255 RMS against 16x the steps (> 2)"

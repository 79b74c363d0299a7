import os
import pathlib

import pytest

SOURCE_DIR = pathlib.Path(os.environ.get("ATLAS_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))

SMALL_GRAPH = """atlas: 1
nodes:
  base:
    type: noise/value
    params: {resolution: [16, 8, 4], bounds_min: [0, 0, 0], bounds_max: [160, 80, 40], octaves: 2, seed: 3}
  coverage:
    type: math/remap
    inputs: {in: base}
    params: {in_min: 0.25, in_max: 0.75, out_min: 0, out_max: 1, clamp: true}
outputs:
  - {node: coverage, file: density.exr}
"""


@pytest.fixture
def quickstart():
    return SOURCE_DIR / "examples" / "quickstart.yaml"


@pytest.fixture
def small_graph():
    return SMALL_GRAPH

"""atlas.Session from Python: load, set, cook, get; fields as NumPy views; errors; callbacks."""
import gc
import os
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

import atlas


def remap(v, lo, hi):
    return np.clip((v.astype(np.float64) - lo) / (hi - lo), 0.0, 1.0)


def test_quickstart_fields_are_zero_copy_readonly_views(quickstart):
    s = atlas.Session()
    s.load(quickstart)
    f = s.get("coverage", jobs=2)
    assert isinstance(f, atlas.Field3D)
    assert f.resolution == (128, 128, 32)
    assert f.shape == (32, 128, 128)
    assert f.bounds == ((0.0, 0.0, 0.0), (4096.0, 4096.0, 1024.0))
    assert f.voxel_size == (32.0, 32.0, 32.0)
    assert f.channel_names == ["density"]
    a = f["density"]
    assert a.dtype == np.float32 and a.shape == (32, 128, 128)
    assert not a.flags.writeable
    with pytest.raises(ValueError):
        a[0, 0, 0] = 1.0
    # No copy: every view of the channel is the same memory.
    assert np.shares_memory(a, f.channel(0))
    assert a.__array_interface__["data"][0] == f[0].__array_interface__["data"][0]
    # to_numpy is the explicit copy.
    c = f.to_numpy()
    assert c.shape == (1, 32, 128, 128) and c.flags.writeable and not np.shares_memory(c, a)
    # Clouds and sky both present, all within [0, 1].
    assert 0.0 == a.min() and a.max() <= 1.0 and 0 < np.count_nonzero(a) < a.size


def test_array_keeps_value_alive(quickstart):
    s = atlas.Session()
    s.load(quickstart)
    a = s.get("base")["density"]
    expected = a.copy()
    del s
    gc.collect()
    junk = [np.full(a.shape, 7.0, np.float32) for _ in range(4)]  # reuse freed memory, if it were freed
    assert np.array_equal(a, expected)
    del junk


def test_values_match_an_independent_reference(small_graph):
    s = atlas.Session()
    s.load_text(small_graph, "small.yaml")
    base = s.get("base", jobs=1)["density"]
    cov = s.get("coverage", jobs=1)["density"]
    assert base.shape == (4, 8, 16)
    assert np.unique(base).size > 10
    np.testing.assert_allclose(cov, remap(base, 0.25, 0.75), atol=1e-6)


def test_incremental_recook_and_report(small_graph):
    s = atlas.Session()
    s.load_text(small_graph, "small.yaml")
    r1 = s.cook(jobs=1)
    assert {n: r1["nodes"][n]["status"] for n in ("base", "coverage")} == {"base": "cooked", "coverage": "cooked"}
    s.set("coverage", "in_min", 0.5)
    r2 = s.cook(jobs=1)
    assert r2["nodes"]["coverage"]["status"] == "cooked"
    assert r2["nodes"]["base"]["status"] == "cached"
    base = s.get("base")["density"]
    np.testing.assert_allclose(s.get("coverage")["density"], remap(base, 0.5, 0.75), atol=1e-6)
    # An int where a float is declared, a float with an integral value where an int is.
    s.set("coverage", "in_min", 0)
    s.set("base", "octaves", 3.0)
    s.set("base", "resolution", [8, 8, 2])
    s.set_text("base", "seed", "11")
    nodes = {n["name"]: n for n in s.nodes()}
    assert nodes["base"]["params"]["octaves"] == 3
    assert nodes["base"]["params"]["resolution"] == [8, 8, 2]
    assert nodes["base"]["params"]["seed"] == 11
    assert nodes["base"]["params"]["gain"] == 0.5  # a default
    assert "gain" not in nodes["base"]["explicit"]
    assert nodes["coverage"]["inputs"] == {"in": ("base", "")}
    assert s.get("coverage").resolution == (8, 8, 2)


def test_write_outputs(tmp_path, small_graph):
    s = atlas.Session()
    s.load_text(small_graph, "small.yaml", base_dir=tmp_path)
    r = s.cook(write_outputs=True, out_dir=tmp_path, jobs=1)
    assert (tmp_path / "density.exr").stat().st_size > 0
    assert r["outputs"][0]["file"] == "density.exr"
    assert s.outputs()[0]["node"] == "coverage"


def test_set_errors(small_graph):
    s = atlas.Session()
    s.load_text(small_graph, "small.yaml")
    with pytest.raises(atlas.Error) as e:
        s.set("base", "octaves", 99)
    assert "base" in str(e.value) and "octaves" in str(e.value) and "16" in str(e.value)
    with pytest.raises(atlas.Error, match="did you mean 'octaves'"):
        s.set("base", "octavs", 2)
    with pytest.raises(atlas.Error, match="nobody"):
        s.set("nobody", "x", 1)
    with pytest.raises(TypeError, match="base.octaves"):
        s.set("base", "octaves", "many")
    with pytest.raises(TypeError):
        s.set("coverage", "clamp", 1)  # a bool parameter takes a bool
    with pytest.raises(atlas.Error, match="no graph"):
        atlas.Session().cook()


BROKEN = """atlas: 1
nodes:
  base:
    type: noise/value
    params: {octavs: 2}
"""


def test_parse_error_carries_the_location():
    s = atlas.Session()
    with pytest.raises(atlas.ParseError) as e:
        s.load_text(BROKEN, "broken.yaml")
    err = e.value
    assert isinstance(err, atlas.Error) and isinstance(err, RuntimeError)
    assert (err.file, err.line) == ("broken.yaml", 5) and err.column > 0
    assert err.where == f"broken.yaml:5:{err.column}"
    assert str(err).startswith(f"broken.yaml:5:{err.column}: error: ")
    assert "did you mean 'octaves'" in err.detail
    with pytest.raises(atlas.ParseError):
        s.load_text("atlas: 1\nnodes: [\n", "bad.yaml")


def test_errors_match_the_cli(tmp_path):
    atlas_bin = os.environ.get("ATLAS_BIN")
    if not atlas_bin or not os.path.exists(atlas_bin):
        pytest.skip("ATLAS_BIN (the atlas CLI) not given")
    graph = tmp_path / "broken.yaml"
    graph.write_text(BROKEN)
    with pytest.raises(atlas.ParseError) as e:
        atlas.Session().load(graph)
    cli = subprocess.run([atlas_bin, "validate", str(graph)], capture_output=True, text=True)
    assert cli.returncode != 0
    assert str(e.value) in cli.stderr
    # An out-of-range override: the same words as --set.
    good = tmp_path / "good.yaml"
    good.write_text(BROKEN.replace("octavs", "octaves") + "outputs:\n  - {node: base, file: base.exr}\n")
    s = atlas.Session()
    s.load(good)
    with pytest.raises(atlas.Error) as e:
        s.set_text("base", "octaves", "99")
    cli = subprocess.run([atlas_bin, "cook", str(good), "--out", str(tmp_path / "out"), "--set", "base.octaves=99"],
                         capture_output=True, text=True)
    assert cli.returncode != 0
    assert str(e.value) in cli.stderr


def test_progress_and_cancel(small_graph):
    s = atlas.Session()
    s.load_text(small_graph, "small.yaml")
    events = []
    lock = threading.Lock()

    def progress(fraction, task, done, total):
        with lock:
            events.append((fraction, task, done, total))

    s.cook(jobs=2, progress=progress)
    assert events
    assert all(0.0 <= f <= 1.0 and isinstance(t, str) and 0 <= d <= n for f, t, d, n in events)

    polls = []
    s.set("coverage", "in_min", 0.3)
    with pytest.raises(atlas.CancelledError):
        s.cook(jobs=1, cancel=lambda: polls.append(1) or True)
    assert polls
    assert s.cook(jobs=1)["nodes"]["coverage"]["status"] == "cooked"  # still usable

    def broken_progress(*args):
        raise ValueError("status bar is gone")

    s.set("coverage", "in_min", 0.35)
    with pytest.raises(atlas.Error, match="status bar is gone"):
        s.cook(jobs=1, progress=broken_progress)


def test_a_one_shot_cook_keeps_no_values(small_graph, tmp_path):
    s = atlas.Session()
    s.load_text(small_graph, "small.yaml")
    r1 = s.cook(jobs=1, keep_values=False, write_outputs=True, out_dir=str(tmp_path))
    assert r1["nodes"]["coverage"]["status"] == "cooked"
    # Nothing kept: the next cook cooks every node again; a session that keeps its values does not.
    r2 = s.cook(jobs=1, keep_values=False)
    assert {r2["nodes"][n]["status"] for n in ("base", "coverage")} == {"cooked"}
    r3 = s.cook(jobs=1)
    assert r3["nodes"]["coverage"]["status"] == "cooked"
    assert s.cook(jobs=1)["nodes"]["coverage"]["status"] == "cached"


def test_cook_releases_the_gil(quickstart):
    s = atlas.Session()
    s.load(quickstart)
    ticks = [0]
    stop = threading.Event()

    def ticker():
        while not stop.is_set():
            ticks[0] += 1
            time.sleep(0.001)

    t = threading.Thread(target=ticker)
    t.start()
    try:
        time.sleep(0.01)
        before = ticks[0]
        t0 = time.perf_counter()
        s.cook(jobs=1)  # noise, SDF and the NVDF set: a fraction of a second or more
        elapsed = time.perf_counter() - t0
        during = ticks[0] - before
    finally:
        stop.set()
        t.join()
    assert elapsed > 0.05, "the cook was too short to tell"
    # With the GIL held for the whole cook the ticker could not have run at all.
    assert during >= 5, f"ticker ran {during} times during a {elapsed:.2f} s cook"


def test_declarations_are_plain_data():
    types = {t["name"]: t for t in atlas.node_types()}
    assert "noise/value" in types and "math/remap" in types
    v = types["noise/value"]
    assert v["version"] >= 1 and v["doc"]
    assert v["inputs"] == []
    assert v["outputs"][0]["name"] == "out" and v["outputs"][0]["type"] == "field3d"
    params = {p["name"]: p for p in v["params"]}
    assert params["octaves"] == {"name": "octaves", "type": "int", "default": 3, "min": 1.0, "max": 16.0,
                                 "unit": "", "doc": params["octaves"]["doc"], "choices": []}
    assert params["octaves"]["doc"]
    assert params["resolution"]["type"] == "int3" and params["resolution"]["unit"] == "voxels"
    assert params["bounds_max"]["default"] == [4096.0, 4096.0, 512.0]
    remap_in = types["math/remap"]["inputs"][0]
    assert remap_in == {"name": "in", "type": "field", "doc": remap_in["doc"], "optional": False}
    s = atlas.Session()
    assert s.declaration("math/remap") == types["math/remap"]
    with pytest.raises(atlas.Error, match="did you mean 'math/remap'"):
        s.declaration("math/remapp")


def test_two_dimensional_fields():
    graph = """atlas: 1
nodes:
  flat:
    type: ndf/constant
    params: {resolution: [6, 4], bounds_min: [0, 0], bounds_max: [600, 400], value: 0.25}
outputs: []
"""
    s = atlas.Session()
    s.load_text(graph, "flat.yaml")
    f = s.get("flat")
    assert isinstance(f, atlas.Field2D)
    assert f.resolution == (6, 4) and f.shape == (4, 6)
    assert f.bounds == ((0.0, 0.0), (600.0, 400.0))
    assert f["value"].shape == (4, 6) and np.all(f["value"] == 0.25)
    assert not f["value"].flags.writeable


def test_field_from_numpy():
    data = np.arange(24, dtype=np.float32).reshape(2, 3, 4)
    f = atlas.Field3D(data, ((0, 0, 0), (4, 3, 2)), ["a"])
    assert f.resolution == (4, 3, 2) and f.channel_names == ["a"]
    assert np.array_equal(f["a"], data) and not np.shares_memory(f["a"], data)
    with pytest.raises(KeyError, match="channels: a"):
        f["b"]
    g = atlas.Field2D(np.zeros((2, 5, 4)), ((0, 0), (1, 1)))
    assert g.channels == 2 and g.shape == (5, 4)
    with pytest.raises(ValueError):
        atlas.Field3D(np.zeros((2, 2)), ((0, 0, 0), (1, 1, 1)))


def test_one_call_at_a_time_per_session(small_graph):
    s = atlas.Session()
    s.load_text(small_graph, "small.yaml")
    started, release = threading.Event(), threading.Event()
    errors = []

    def hold():  # the cancel callback keeps the cook running until released
        started.set()
        release.wait(10)
        return False

    def cook():
        try:
            s.cook(jobs=1, cancel=hold)
        except Exception as e:  # pragma: no cover - reported below
            errors.append(e)

    t = threading.Thread(target=cook)
    t.start()
    try:
        assert started.wait(10)
        with pytest.raises(atlas.Error, match="in use by another thread"):
            s.set("coverage", "in_min", 0.5)
        with pytest.raises(atlas.Error, match="in use by another thread"):
            s.nodes()
        other = atlas.Session()  # another Session is independent
        other.load_text(small_graph, "other.yaml")
        assert other.get("coverage").resolution == (16, 8, 4)
    finally:
        release.set()
        t.join()
    assert not errors
    s.set("coverage", "in_min", 0.5)  # free again


def test_two_sessions_in_two_threads_before_numpy_is_imported(small_graph, tmp_path):
    """Issue 48: with numpy not yet imported, two threads with their own Sessions
    deadlocked on their first field access (3 of 3). A fresh interpreter, so
    nothing here has imported numpy first."""
    script = tmp_path / "two_threads.py"
    script.write_text(
        "import sys, threading\n"
        "assert 'numpy' not in sys.modules\n"
        "import atlas\n"
        f"GRAPH = {small_graph!r}\n"
        "out = []\n"
        "def work(i):\n"
        "    s = atlas.Session()\n"
        "    s.load_text(GRAPH, f'g{i}.yaml')\n"
        "    out.append(float(s.get('coverage').channel(0).sum()))\n"
        "ts = [threading.Thread(target=work, args=(i,)) for i in range(2)]\n"
        "[t.start() for t in ts]\n"
        "[t.join() for t in ts]\n"
        "assert len(out) == 2 and out[0] == out[1], out\n"
        "print('ok')\n")
    env = dict(os.environ)
    for _ in range(3):
        r = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=120, env=env)
        assert r.returncode == 0, r.stderr
        assert r.stdout.strip() == "ok"


def test_cook_requirements_grows_the_missing_input_first(tmp_path):
    # A graph reading another graph's output (requires:) cooks on a fresh clone from Python too.
    (tmp_path / "maker.yaml").write_text(
        "atlas: 1\nnodes:\n  n:\n    type: noise/value\n    params: {resolution: [8, 8, 8], bounds_max: [80, 80, 80]}\n"
        "outputs:\n  - {node: n, file: cloud.vdb}\n")
    (tmp_path / "reader.yaml").write_text(
        "atlas: 1\nrequires:\n  - {graph: maker.yaml, out: made}\nnodes:\n  in:\n    type: import/vdb\n"
        "    params: {file: made/cloud.vdb, grids: density}\noutputs:\n  - {node: in, file: in.vdb}\n")
    s = atlas.Session()
    s.load(tmp_path / "reader.yaml")
    with pytest.raises(atlas.Error, match="cloud.vdb"):
        s.cook()
    done = s.cook_requirements(jobs=1)
    assert [f for f, _ in done] == [str(tmp_path / "maker.yaml")]
    assert done[0][1]["nodes"]["n"]["status"] == "cooked"
    assert (tmp_path / "made" / "cloud.vdb").exists()
    assert s.cook_requirements() == []
    np.testing.assert_allclose(s.get("in")["density"].shape, (8, 8, 8))


CLOUD_GRAPH = """atlas: 1
nodes:
  density: {type: volume/metaballs, params: {resolution: [32, 32, 16], bounds_max: [1000, 1000, 500], kernel: sphere, blend: max,
            spheres: 500 500 220 160; 640 520 240 110}}
  sdf: {type: volume/sdf, inputs: {in: density}, params: {iso: 0.5}}
  nvdf: {type: volume/nvdf, inputs: {sdf: sdf}, params: {depth: 30}}
outputs:
  - {node: nvdf, port: vdb_set, file: cloud.vdb}
"""


def test_preview_is_the_cli_picture_and_proxies_never_write(tmp_path):
    # Session.preview and `atlas preview` call one library entry: the same linear
    # picture, the CLI's read back with OpenImageIO (rows from the top in both).
    import OpenImageIO as oiio
    (tmp_path / "cloud.yaml").write_text(CLOUD_GRAPH)
    s = atlas.Session()
    s.load(tmp_path / "cloud.yaml")
    img = s.preview({"size": (40, 24), "view": "orbit", "sun_azimuth": 200}, noise="none")
    assert img.shape == (24, 40, 4) and img.dtype == np.float32
    subprocess.run([os.environ["ATLAS_BIN"], "preview", str(tmp_path / "cloud.yaml"), "--size", "40x24", "--view", "orbit", "--sun", "200,25",
                    "--noise", "none", "--no-cache", "--quiet", "-o", str(tmp_path / "cli.exr")], check=True)
    cli = oiio.ImageBuf(str(tmp_path / "cli.exr")).get_pixels(oiio.FLOAT)
    np.testing.assert_array_equal(img, cli)
    t = img[..., 3]
    assert t.min() < 0.5 and t.max() > 0.99  # a cloud in front of the sky
    # The PNG's values; at a proxy (half the cells) a similar picture.
    png = s.preview({"size": "40x24", "view": "orbit"}, noise="none", tone_mapped=True)
    assert png.shape == (24, 40, 3) and 0 <= png.min() and png.max() <= 1
    half = s.preview({"size": (40, 24), "view": "orbit", "sun_azimuth": 200}, noise="none", proxy=2)
    assert np.abs(half[..., 3] - t).mean() < 0.1
    with pytest.raises(atlas.Error, match="never written as final outputs"):
        s.cook(proxy=2, write_outputs=True, out_dir=tmp_path / "out")
    assert not (tmp_path / "out").exists()
    with pytest.raises(atlas.Error, match="preview option 'sizes' does not exist"):
        s.preview({"sizes": 3})


def test_set_time_moves_keyed_parameters(tmp_path):
    s = atlas.Session()
    s.load_text("""atlas: 1
time: {start: 0, end: 10, fps: 1}
nodes:
  keyed:
    type: field/constant
    params: {resolution: [2, 2, 1], value: {keys: [[0, 1], [10, 3]], interp: smooth}}
  still:
    type: field/constant
    params: {resolution: [2, 2, 1], value: 4}
outputs: []
""", name="time.yaml", base_dir=str(tmp_path))
    assert s.time_range() == (0.0, 10.0, 1.0)
    assert float(s.get("keyed").channel(0).flat[0]) == 1.0
    s.set_time(5)
    assert float(s.get("keyed").channel(0).flat[0]) == 2.0  # smoothstep at half way: half
    s.set_time(2.5)
    assert float(s.get("keyed").channel(0).flat[0]) == pytest.approx(1.3125)  # 1 + 2 (3u^2 - 2u^3), u = 1/4
    assert float(s.get("still").channel(0).flat[0]) == 4.0
    with pytest.raises(atlas.Error):
        s.set_time(float("nan"))

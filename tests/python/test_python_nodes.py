"""Node types written in Python: declared as plain data, cooked with NumPy, hashed and cached."""
import numpy as np
import pytest

import atlas

GRAPH = """atlas: 1
nodes:
  base:
    type: noise/value
    params: {resolution: [16, 8, 4], bounds_min: [0, 0, 0], bounds_max: [160, 80, 40], octaves: 2, seed: 3}
  gained:
    type: py/gain
    inputs: {in: base}
    params: {gain: 3}
  shaped:                      # a built-in node reading the Python node's output
    type: math/remap
    inputs: {in: gained}
    params: {in_min: 0, in_max: 3}
outputs:
  - {node: shaped, file: shaped.exr}
"""

GAIN_DECL = dict(
    doc="Multiplies a field by a gain.",
    inputs=[{"name": "in", "type": "field3d", "doc": "field to scale"}],
    outputs=[{"name": "out", "type": "field3d", "doc": "scaled field"}],
    params=[{"name": "gain", "type": "float", "default": 2.0, "min": 0.0, "max": 10.0, "unit": "", "doc": "factor"}],
)


def make_registry(calls):
    def cook(ctx):
        calls.append(ctx.node_name)
        src = ctx.input("in")
        out = np.stack([src[c] * ctx.params["gain"] for c in range(len(src))])
        ctx.set_output("out", out, channel_names=src.channel_names)  # bounds: the input's
        ctx.metric("gain", ctx.param("gain"))

    reg = atlas.builtin_nodes()
    reg.add_python_node("py/gain", cook, version=1, **GAIN_DECL)
    return reg


def test_python_node_cooks_hashes_and_caches():
    calls = []
    s = atlas.Session(make_registry(calls))
    s.load_text(GRAPH, "py.yaml")
    r = s.cook(jobs=2)
    assert calls == ["gained"]
    assert r["nodes"]["gained"]["status"] == "cooked"
    assert r["nodes"]["gained"]["metrics"] == {"gain": 3.0}
    base = s.get("base")
    gained = s.get("gained")
    assert gained.bounds == base.bounds and gained.channel_names == base.channel_names
    np.testing.assert_allclose(gained["density"], base["density"] * 3, rtol=1e-6)
    np.testing.assert_allclose(s.get("shaped")["density"], np.clip(base["density"], 0, 1), atol=1e-6)

    # Nothing changed: served from the cache, the Python function is not called.
    r = s.cook(jobs=2)
    assert calls == ["gained"] and r["nodes"]["shaped"]["status"] == "cached"
    assert r["nodes"]["gained"]["status"] != "cooked"  # not even loaded: its consumer was cached
    # A parameter change re-cooks it (validated against the Python declaration).
    s.set("gained", "gain", 0.5)
    assert s.cook(jobs=1)["nodes"]["gained"]["status"] == "cooked" and len(calls) == 2
    np.testing.assert_allclose(s.get("gained")["density"], base["density"] * 0.5, rtol=1e-6)
    with pytest.raises(atlas.Error, match="gain"):
        s.set("gained", "gain", 11.0)


def test_python_node_declaration_round_trips():
    reg = make_registry([])
    d = reg.declaration("py/gain")
    assert d["name"] == "py/gain" and d["version"] == 1 and d["doc"] == GAIN_DECL["doc"]
    assert d["inputs"] == [{"name": "in", "type": "field3d", "doc": "field to scale", "optional": False}]
    assert d["params"] == [{"name": "gain", "type": "float", "default": 2.0, "min": 0.0, "max": 10.0,
                            "unit": "", "doc": "factor", "choices": []}]
    # The plain data atlas gives back registers the same node again.
    reg2 = atlas.NodeRegistry()
    reg2.add_python_node("py/gain", lambda ctx: None, **{k: d[k] for k in ("doc", "inputs", "outputs", "params")})
    assert reg2.declaration("py/gain") == d
    assert "py/gain" in reg and len(reg2) == 1


def test_hash_follows_the_code_and_the_version():
    def hashes(cook, version=1):
        reg = atlas.builtin_nodes()
        reg.add_python_node("py/gain", cook, version=version, **GAIN_DECL)
        s = atlas.Session(reg)
        s.load_text(GRAPH, "py.yaml")
        return s.node_hashes()

    def times(ctx):
        ctx.set_output("out", ctx.input("in")[0] * ctx.params["gain"])

    def plus(ctx):
        ctx.set_output("out", ctx.input("in")[0] + ctx.params["gain"])

    a, b, c = hashes(times), hashes(plus), hashes(times, version=2)
    assert a == hashes(times)
    assert a["base"] == b["base"] == c["base"]
    assert len({a["gained"], b["gained"], c["gained"]}) == 3
    assert a["shaped"] != b["shaped"]  # downstream follows


def test_pass_through_and_generated_fields():
    def passthrough(ctx):
        ctx.set_output("out", ctx.input("in"))  # the input value itself: no copy

    def ramp(ctx):
        nx, ny, nz = ctx.params["resolution"]
        z = np.linspace(0, 1, nz, dtype=np.float32)[:, None, None]
        ctx.set_output("out", np.broadcast_to(z, (nz, ny, nx)), bounds=((0, 0, 0), ctx.params["size"]))

    reg = atlas.builtin_nodes()
    reg.add_python_node("py/pass", passthrough, inputs=[{"name": "in", "type": "field"}],
                        outputs=[{"name": "out", "type": "field"}])
    reg.add_python_node("py/ramp", ramp, outputs=[{"name": "out", "type": "field3d"}],
                        params=[{"name": "resolution", "type": "int3", "default": [4, 3, 5], "min": 1},
                                {"name": "size", "type": "float3", "default": [40, 30, 50], "unit": "m"}])
    s = atlas.Session(reg)
    s.load_text("""atlas: 1
nodes:
  ramp: {type: py/ramp}
  same: {type: py/pass, inputs: {in: ramp}}
outputs: []
""", "gen.yaml")
    ramp_f = s.get("ramp")
    assert ramp_f.resolution == (4, 3, 5) and ramp_f.bounds == ((0, 0, 0), (40, 30, 50))
    np.testing.assert_allclose(ramp_f[0][:, 1, 2], np.linspace(0, 1, 5), rtol=1e-6)
    assert np.shares_memory(s.get("same")[0], ramp_f[0])


def test_python_errors_name_the_node():
    def broken(ctx):
        raise ValueError("no clouds today")

    def wrong_shape(ctx):
        ctx.set_output("out", np.zeros(3))

    def no_bounds(ctx):
        ctx.set_output("out", np.zeros((2, 2, 2)))

    reg = atlas.builtin_nodes()
    out = [{"name": "out", "type": "field3d"}]
    reg.add_python_node("py/broken", broken, outputs=out)
    reg.add_python_node("py/shape", wrong_shape, outputs=out)
    reg.add_python_node("py/nobounds", no_bounds, outputs=out)
    s = atlas.Session(reg)
    s.load_text("atlas: 1\nnodes:\n  a: {type: py/broken}\n  b: {type: py/shape}\n  c: {type: py/nobounds}\noutputs: []\n", "err.yaml")
    with pytest.raises(atlas.Error, match=r"node 'a' \(py/broken\): .*ValueError: no clouds today"):
        s.get("a")
    with pytest.raises(atlas.Error, match=r"node 'b'.*\(nz, ny, nx\)"):
        s.get("b")
    with pytest.raises(atlas.Error, match=r"node 'c'.*bounds"):
        s.get("c")
    # A context used after its cook is refused, not a crash.
    kept = []
    reg2 = atlas.builtin_nodes()
    reg2.add_python_node("py/keep", lambda ctx: (kept.append(ctx), ctx.set_output("out", np.zeros((1, 1, 1)), bounds=((0, 0, 0), (1, 1, 1)))),
                         outputs=out)
    s2 = atlas.Session(reg2)
    s2.load_text("atlas: 1\nnodes:\n  k: {type: py/keep}\noutputs: []\n", "keep.yaml")
    s2.get("k")
    with pytest.raises(atlas.Error, match="only valid during"):
        kept[0].params


def test_bad_declarations_are_refused():
    reg = atlas.NodeRegistry()
    with pytest.raises(ValueError, match="port type"):
        reg.add_python_node("py/x", lambda ctx: None, outputs=[{"name": "out", "type": "volume"}])
    with pytest.raises(ValueError, match="at least one output"):
        reg.add_python_node("py/x", lambda ctx: None)
    with pytest.raises(ValueError, match="default"):
        reg.add_python_node("py/x", lambda ctx: None, outputs=[{"name": "out"}],
                            params=[{"name": "g", "type": "float", "default": 20.0, "max": 10.0}])
    with pytest.raises(TypeError):
        reg.add_python_node("py/x", 42, outputs=[{"name": "out"}])


def test_python_nodes_in_parallel():
    def cook(ctx):
        ctx.progress(0.5)
        ctx.set_output("out", ctx.input("in")[0] + 1.0)

    reg = atlas.builtin_nodes()
    reg.add_python_node("py/inc", cook, inputs=[{"name": "in", "type": "field3d"}], outputs=[{"name": "out", "type": "field3d"}])
    branches = "".join(f"  p{i}: {{type: py/inc, inputs: {{in: base}}}}\n" for i in range(6))
    s = atlas.Session(reg)
    s.load_text("atlas: 1\nnodes:\n  base: {type: noise/value, params: {resolution: [8, 8, 8]}}\n" + branches + "outputs: []\n", "par.yaml")
    s.cook(jobs=2, progress=lambda *a: None)
    base = s.get("base")[0]
    for i in range(6):
        np.testing.assert_allclose(s.get(f"p{i}")[0], base + 1.0, rtol=1e-6)


def test_python_node_output_keeps_the_input_channel_names():
    # The docs' own example (docs/embedding.md) passes no channel_names: the output is named
    # after the first field input of the same dimensionality and channel count.
    def gain(ctx):
        ctx.set_output("out", ctx.input("in")["density"] * ctx.params["gain"])

    def split(ctx):  # two channels from a one-channel input: no name to inherit
        d = ctx.input("in")["density"]
        ctx.set_output("out", np.stack([d, 1 - d]))

    reg = atlas.builtin_nodes()
    reg.add_python_node("py/gain", gain, version=1, **GAIN_DECL)
    reg.add_python_node("py/split", split, version=1, **{**GAIN_DECL, "doc": "Splits a field in two."})
    s = atlas.Session(reg)
    s.load_text(GRAPH.replace("outputs:", """  two:
    type: py/split
    inputs: {in: base}
outputs:
  - {node: two, file: two.exr}""", 1), "names.yaml")
    s.cook(jobs=1)
    assert s.get("gained").channel_names == ["density"]
    assert s.get("shaped").channel_names == ["density"]
    assert s.get("two").channel_names == ["r", "g"]

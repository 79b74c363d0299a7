"""Atlas for Blender: open an Atlas node graph, edit its parameters, cook it and see the result.

The panel (View3D > Sidebar > Atlas, and Properties > Scene) opens a graph file, lists every node's parameters from the
node declarations (with ranges and units; hover the (i) button for the doc), cooks in a background
thread with Blender's progress indicator (Cancel stops it), re-cooks incrementally when a parameter
changes, and shows VDB outputs (the NVDF set) as Volume objects in world units (metres) with a
volume material that approximates the Nubis look, and 2D outputs (NDFs) as float images.

It needs the `atlas` Python module (python/ in the Atlas build): set its directory in the add-on's
preferences, or ATLAS_PYTHONPATH, or put it on Blender's sys.path. Debian's Blender 3.4 runs the
system Python 3.11 that the module is built for.
"""

bl_info = {
    "name": "Atlas clouds",
    "author": "Atlas",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "View3D > Sidebar > Atlas",
    "description": "Cook Atlas node graphs (volumetric cloud data) and load their VDBs and NDFs",
    "category": "Import-Export",
}

import math
import os
import shutil
import sys
import tempfile
import threading
import time

import bpy
from bpy.props import (BoolProperty, CollectionProperty, FloatProperty, FloatVectorProperty, IntProperty,
                       IntVectorProperty, PointerProperty, StringProperty)

# ---------------------------------------------------------------- the atlas module


def _atlas_module():
    """Imports atlas, adding the configured directory to sys.path first."""
    candidates = []
    try:
        prefs = bpy.context.preferences.addons[__name__].preferences
        if prefs.atlas_python_path:
            candidates.append(bpy.path.abspath(prefs.atlas_python_path))
    except (KeyError, AttributeError):
        pass
    if os.environ.get("ATLAS_PYTHONPATH"):
        candidates.append(os.environ["ATLAS_PYTHONPATH"])
    for c in candidates:
        if c and c not in sys.path:
            sys.path.insert(0, c)
    import atlas  # noqa: F401 (raises ImportError with Python's message when not found)

    return atlas


# ---------------------------------------------------------------- per-scene state
# Blender properties cannot hold Python objects: the Session and the running cook live here,
# keyed by scene name. Only the main thread touches bpy; the cook thread touches only the job.


class CookJob:
    """A cook on a worker thread. "export": every output written at full resolution into out_dir (the
    Cook button). "view" (an edit with Re-cook on change): only what the viewport shows, as values at
    the scene's proxy, nothing written to out_dir: each VDB output into a new file of its own in the
    add-on's scratch folder (a new path, so Blender loads the new grids), 2D outputs as values, and
    the Atlas preview picture."""

    def __init__(self, session, out_dir, view=None):
        self.session = session
        self.out_dir = out_dir
        self.view = view  # None, or {"dir", "serial", "proxy", "outputs": [(out, port, is_vdb)], "preview": (w, h) | None}
        self.cancel = threading.Event()
        self.fraction = 0.0
        self.task = ""
        self.report = None
        self.error = None
        self.thread = None
        self.volumes = {}   # stem -> the VDB file to show
        self.images = {}    # stem -> a cooked 2D field
        self.picture = None  # the preview's sRGB pixels (h, w, 3)
        self.seconds = 0.0
        self.failed = []  # "output: error" of outputs that failed in a view

    def run(self, jobs):
        def progress(fraction, task, done, total):
            self.fraction, self.task = fraction, task

        t0 = time.perf_counter()
        try:
            if self.view is None:
                # keep_going: an output a slider move made unwritable (a DDS bound out of reach) is a
                # warning on that output; the other outputs, and the viewport, still update.
                self.report = self.session.cook(jobs=jobs, write_outputs=True, out_dir=self.out_dir, progress=progress,
                                                cancel=self.cancel.is_set, keep_going=True)
            else:
                self._run_view(jobs, progress)
        except Exception as e:  # atlas.Error and its subclasses; shown in the panel
            self.error = e
        self.seconds = time.perf_counter() - t0

    def _run_view(self, jobs, progress):
        v = self.view
        for out, port, is_vdb in v["outputs"]:
            stem = "atlas_" + os.path.splitext(os.path.basename(out["file"]))[0]
            try:
                value = self.session.get(out["node"], port, jobs=jobs, proxy=v["proxy"], progress=progress, cancel=self.cancel.is_set)
            except Exception as e:
                if type(e).__name__ == "CancelledError":
                    raise
                # One output that fails is a warning on it; the rest of the view updates.
                self.failed.append(f"{out['file']}: {e}")
                continue
            if is_vdb:
                path = os.path.join(v["dir"], f"{stem}.{v['serial']}.vdb")
                value.write(path, "vdb")
                self.volumes[stem] = path
            else:
                self.images[stem] = value
        if v["preview"]:
            try:
                self.picture = self.session.preview({"size": v["preview"]}, proxy=v["proxy"], jobs=jobs, tone_mapped=True,
                                                    progress=progress, cancel=self.cancel.is_set)
            except Exception as e:
                if type(e).__name__ == "CancelledError":
                    raise
                self.failed.append(f"preview: {e}")

    def done(self):
        return self.thread is None or not self.thread.is_alive()


# scene name -> {"session": atlas.Session, "job": CookJob | None, "again": bool, "pending": [(node, param, value)]}
_state = {}


def _scene_state(scene):
    return _state.setdefault(scene.name, {"session": None, "job": None, "again": False, "pending": []})


def _apply_edit(scene, node, param, value):
    """Session.set on the main thread, never while a cook runs (a Session is one call at a time)."""
    try:
        _scene_state(scene)["session"].set(node, param, value)
        scene.atlas.error = ""
        return True
    except Exception as e:
        scene.atlas.error = str(e)
        return False


# ---------------------------------------------------------------- properties

_VECTOR_TYPES = {"float2": 2, "float3": 3, "int2": 2, "int3": 3}


def _on_param_changed(self, context):
    if getattr(_on_param_changed, "loading", False):
        return
    scene = context.scene
    props = scene.atlas
    st = _scene_state(scene)
    if st["session"] is None:
        return
    job = st["job"]
    if job is not None and not job.done():
        # The session is cooking on its thread: stop that cook, edit when it has returned.
        st["pending"].append((self.node, self.name, self.value()))
        job.cancel.set()
        st["again"] = st["again"] or props.auto_cook
        return
    if not _apply_edit(scene, self.node, self.name, self.value()):
        # Refused (the library's message is in the panel): the field returns to the value the
        # session holds, the last good one.
        node = next((n for n in st["session"].nodes() if n["name"] == self.node), None)
        if node is not None:
            _on_param_changed.loading = True
            try:
                self.assign(node["params"][self.name])
            finally:
                _on_param_changed.loading = False
        return
    if props.auto_cook:
        start_cook(scene, background=not bpy.app.background, view=True)


class AtlasParam(bpy.types.PropertyGroup):
    node: StringProperty()
    node_type: StringProperty()
    name: StringProperty()
    ptype: StringProperty()
    unit: StringProperty()
    doc: StringProperty()
    range_text: StringProperty()
    choices: StringProperty()  # comma-separated, for enums (edited as text, validated by Atlas)
    f: FloatProperty(update=_on_param_changed, precision=4)
    i: IntProperty(update=_on_param_changed)
    b: BoolProperty(update=_on_param_changed)
    s: StringProperty(update=_on_param_changed)
    v: FloatVectorProperty(size=3, update=_on_param_changed)
    iv: IntVectorProperty(size=3, update=_on_param_changed)

    def value(self):
        t = self.ptype
        if t == "float":
            return self.f
        if t == "int":
            return self.i
        if t == "bool":
            return self.b
        if t in _VECTOR_TYPES:
            return list(self.iv if t.startswith("int") else self.v)[: _VECTOR_TYPES[t]]
        return self.s

    def assign(self, value):
        t = self.ptype
        if t == "float":
            self.f = float(value)
        elif t == "int":
            self.i = max(-2**31, min(2**31 - 1, int(value)))
        elif t == "bool":
            self.b = bool(value)
        elif t in _VECTOR_TYPES:
            vals = (list(value) + [0] * 3)[:3]
            if t.startswith("int"):
                self.iv = [int(x) for x in vals]
            else:
                self.v = [float(x) for x in vals]
        else:
            self.s = str(value)


class AtlasSceneProps(bpy.types.PropertyGroup):
    graph_path: StringProperty(name="Graph", subtype="FILE_PATH", description="An Atlas graph file (.yaml)")
    out_dir: StringProperty(name="Output", subtype="DIR_PATH",
                            description="Where cooked outputs are written (empty: a temporary directory)")
    jobs: IntProperty(name="Threads", default=0, min=0, description="Cook threads (0: all); results do not depend on it")
    auto_cook: BoolProperty(name="Re-cook on change", default=True,
                            description="Re-cook (incrementally) whenever a parameter changes")
    proxy: IntProperty(name="Proxy", default=1, min=1, max=16,
                       description="Edits cook every world grid at 1/P of its cells per axis (4: a quarter) for a quick look; "
                                   "Cook writes the outputs at full resolution")
    show_preview: BoolProperty(name="Atlas preview", default=True,
                               description="Render Atlas's own preview of each edit into the image 'atlas_preview' (Image Editor)")
    preview_size: IntVectorProperty(name="Preview size", size=2, default=(480, 270), min=16, max=4096)
    show_all: BoolProperty(name="All parameters", default=False,
                           description="Show every declared parameter, not only those the graph sets")
    params: CollectionProperty(type=AtlasParam)
    error: StringProperty()
    status: StringProperty()
    last_cooked: StringProperty()  # names of the nodes the last cook cooked, space-separated


class AtlasPreferences(bpy.types.AddonPreferences):
    bl_idname = __name__
    atlas_python_path: StringProperty(name="atlas Python module", subtype="DIR_PATH",
                                      description="The directory that contains the atlas package (e.g. build/python)")

    def draw(self, context):
        self.layout.prop(self, "atlas_python_path")


# ---------------------------------------------------------------- graph -> properties


def open_graph(scene, path):
    """Loads a graph into the scene's session and lists its parameters. Raises atlas.Error."""
    atlas = _atlas_module()
    props = scene.atlas
    st = _scene_state(scene)
    if st["job"] is not None and not st["job"].done():
        st["job"].cancel.set()
        st["job"].thread.join()
    session = st["session"] or atlas.Session()
    session.load(bpy.path.abspath(path))
    st["session"] = session
    props.graph_path = path
    props.error = ""
    fill_params(scene)


def fill_params(scene):
    props = scene.atlas
    session = _scene_state(scene)["session"]
    decls = {d["name"]: d for d in session.node_types()}
    props.params.clear()
    _on_param_changed.loading = True
    try:
        for node in session.nodes():
            decl = decls[node["type"]]
            for p in decl["params"]:
                item = props.params.add()
                item.node, item.name, item.ptype = node["name"], p["name"], p["type"]
                item.node_type = node["type"]
                item.unit, item.doc = p["unit"], p["doc"]
                lo, hi = p["min"], p["max"]
                item.range_text = "" if lo is None and hi is None else f"[{'' if lo is None else f'{lo:g}'}, {'' if hi is None else f'{hi:g}'}]"
                item.choices = ",".join(p["choices"])
                item.assign(node["params"][p["name"]])
                item["explicit"] = p["name"] in node["explicit"]
    finally:
        _on_param_changed.loading = False


# ---------------------------------------------------------------- cooking


def _out_dir(scene):
    props = scene.atlas
    if props.out_dir:
        return bpy.path.abspath(props.out_dir)
    st = _scene_state(scene)
    if "tmp" not in st:
        st["tmp"] = tempfile.mkdtemp(prefix="atlas_blender_")
    return st["tmp"]


def _scratch_dir(scene):
    """The add-on's own folder for the files the viewport reads (never the output folder)."""
    st = _scene_state(scene)
    if "scratch" not in st:
        st["scratch"] = tempfile.mkdtemp(prefix="atlas_blender_view_")
    return st["scratch"]


def _view_outputs(session):
    """What the viewport shows of a graph's outputs: (output, port, is_vdb) for each VDB output and
    each 2D field output."""
    decls = {d["name"]: d for d in session.node_types()}
    node_types = {n["name"]: n["type"] for n in session.nodes()}
    found = []
    for out in session.outputs():
        ports = decls[node_types[out["node"]]]["outputs"]
        port = next((p for p in ports if p["name"] == (out["port"] or ports[0]["name"])), ports[0])
        if out["format"] == "vdb":
            found.append((out, port["name"], True))
        elif port["type"] == "field2d":
            found.append((out, port["name"], False))
    return found


def _next_serial(scene):
    st = _scene_state(scene)
    st["serial"] = st.get("serial", 0) + 1
    return st["serial"]


def start_cook(scene, background=True, view=False):
    """Cooks the scene's graph. In the background: a thread, polled by a timer that loads the
    results on the main thread; a cook already running is cancelled and cooked again.
    view=True (an edit): what the viewport shows, at the scene's proxy, nothing written to the
    output folder; view=False (the Cook button): every output written at full resolution."""
    st = _scene_state(scene)
    if st["session"] is None:
        raise RuntimeError("open a graph first")
    job = st["job"]
    if job is not None and not job.done():
        job.cancel.set()
        st["again"] = True
        st["again_view"] = st.get("again_view", True) and view
        return
    props = scene.atlas
    spec = None
    if view:
        spec = {"dir": _scratch_dir(scene), "serial": _next_serial(scene), "proxy": props.proxy,
                "outputs": _view_outputs(st["session"]),
                "preview": tuple(props.preview_size) if props.show_preview else None}
    job = CookJob(st["session"], _out_dir(scene), spec)
    st["job"] = job
    props = scene.atlas
    props.status = "cooking"
    if not background:
        job.run(props.jobs)
        _finish(scene, job)
        return
    job.thread = threading.Thread(target=job.run, args=(props.jobs,), daemon=True)
    wm = bpy.context.window_manager
    wm.progress_begin(0, 1)
    job.thread.start()
    scene_name = scene.name

    def poll():
        sc = bpy.data.scenes.get(scene_name)
        if sc is None:
            return None
        if not job.done():
            wm.progress_update(job.fraction)
            sc.atlas.status = f"cooking {job.fraction:.0%} {job.task}"
            _redraw()
            return 0.1
        wm.progress_end()
        _finish(sc, job)
        state = _scene_state(sc)
        edits, state["pending"] = state["pending"], []
        ok = all([_apply_edit(sc, *e) for e in edits])
        if state["again"]:
            state["again"] = False
            view, state["again_view"] = state.get("again_view", True), True
            if ok:
                start_cook(sc, background=True, view=view)
        return None

    bpy.app.timers.register(poll, first_interval=0.1)


def _redraw():
    for window in getattr(bpy.context.window_manager, "windows", []):
        for area in window.screen.areas:
            if area.type == "VIEW_3D":
                area.tag_redraw()


def _finish(scene, job):
    props = scene.atlas
    if job.error is not None:
        # The last good cloud stays in the viewport; the error stays in the panel.
        cancelled = type(job.error).__name__ == "CancelledError"
        props.status = "cancelled" if cancelled else "failed"
        props.error = "" if cancelled else str(job.error)
        return
    if job.view is not None:
        proxy = job.view["proxy"]
        props.status = f"view updated in {job.seconds:.2f} s" + (f" at proxy {proxy}" if proxy > 1 else "") + " (Cook writes the outputs)"
        props.error = "; ".join(job.failed)
        for stem, path in job.volumes.items():
            _load_volume(scene, stem, path)
        for stem, field in job.images.items():
            _field_image(stem, field)
        if job.picture is not None:
            _picture_image("atlas_preview", job.picture)
        return
    report = job.report
    cooked = sorted(n for n, r in report["nodes"].items() if r["status"] == "cooked")
    props.last_cooked = " ".join(cooked)
    props.status = f"cooked {len(cooked)} node(s) in {report['seconds']:.2f} s"
    failed = [o for o in report["outputs"] if o.get("status") == "failed"]
    props.error = "; ".join(f"output '{o['file']}' not written: {o.get('error', '')}" for o in failed)
    load_outputs(scene, job.out_dir)


# ---------------------------------------------------------------- results into the scene


def load_outputs(scene, out_dir):
    """VDB outputs become Volume objects (one per file, grids as in the file, world units);
    2D image outputs become images. Returns the Volume objects."""
    session = _scene_state(scene)["session"]
    decls = {d["name"]: d for d in session.node_types()}
    node_types = {n["name"]: n["type"] for n in session.nodes()}
    volumes = []
    for out in session.outputs():
        path = os.path.join(out_dir, out["file"])
        if not os.path.exists(path):
            continue
        stem = "atlas_" + os.path.splitext(os.path.basename(out["file"]))[0]
        if out["format"] == "vdb":
            volumes.append(_load_volume(scene, stem, path))
        else:
            ports = decls[node_types[out["node"]]]["outputs"]
            port = next((p for p in ports if p["name"] == (out["port"] or ports[0]["name"])), ports[0])
            if port["type"] == "field2d":
                _field_image(stem, session.get(out["node"], port["name"]))
    return volumes


def _field_image(name, field):
    """A 2D field (an NDF) as a float image with its exact values: channels 0..3 as R, G, B, A (one
    channel as grey), row 0 at the bottom as in the field (y up). Made from the cooked value, not
    the file, so that every output format (and EXR channel names Blender does not read) looks the same."""
    import numpy as np

    nx, ny = field.resolution
    img = bpy.data.images.get(name)
    if img is None or tuple(img.size) != (nx, ny):
        if img is not None:
            bpy.data.images.remove(img)
        img = bpy.data.images.new(name, nx, ny, alpha=True, float_buffer=True)
    rgba = np.ones((ny, nx, 4), np.float32)
    if field.channels == 1:
        rgba[..., :3] = field[0][..., None]
    else:
        for c in range(min(4, field.channels)):
            rgba[..., c] = field[c]
    img.pixels.foreach_set(rgba.ravel())
    img.update()
    img["atlas_channels"] = ",".join(field.channel_names)
    return img


def _picture_image(name, pixels):
    """The Atlas preview (sRGB values, rows from the top) as an image for an Image Editor."""
    import numpy as np

    h, w = pixels.shape[:2]
    img = bpy.data.images.get(name)
    if img is None or tuple(img.size) != (w, h):
        if img is not None:
            bpy.data.images.remove(img)
        img = bpy.data.images.new(name, w, h, alpha=True, float_buffer=True)
        img.colorspace_settings.name = "Non-Color"  # the values are already the PNG's
    rgba = np.ones((h, w, 4), np.float32)
    rgba[..., :3] = pixels[::-1]  # Blender's rows start at the bottom
    img.pixels.foreach_set(rgba.ravel())
    img.update()
    return img


def _load_volume(scene, name, path):
    """Shows a VDB as the Volume datablock `name`. Blender keeps a Volume's grids as long as its
    file path does not change (rewriting the file in place showed the old cloud), so every load
    is a new path: the add-on's own files are new already; an output file is linked (or copied)
    under a new name in the scratch folder. The previous file is removed once replaced."""
    st = _scene_state(scene)
    scratch = _scratch_dir(scene)
    if os.path.dirname(os.path.abspath(path)) != os.path.abspath(scratch):
        view = os.path.join(scratch, f"{name}.{_next_serial(scene)}.vdb")
        try:
            os.link(path, view)
        except OSError:
            shutil.copy2(path, view)
        path = view
    vol = bpy.data.volumes.get(name) or bpy.data.volumes.new(name)
    old = vol.filepath
    vol.grids.unload()
    vol.filepath = path
    if not vol.grids.load():
        raise RuntimeError(f"{path}: {vol.grids.error_message}")
    shown = st.setdefault("shown", {})
    if old and old != path and shown.get(name) == old and os.path.dirname(old) == scratch:
        try:
            os.remove(old)
        except OSError:
            pass
    shown[name] = path
    # The viewport draws the active grid: the cloud's shape, not the SDF's whole box.
    names = [g.name for g in vol.grids]
    if "dimensional_profile" in names:
        vol.grids.active_index = names.index("dimensional_profile")
    obj = bpy.data.objects.get(name)
    if obj is None:
        obj = bpy.data.objects.new(name, vol)
        scene.collection.objects.link(obj)
    if not vol.materials:
        vol.materials.append(nubis_material(vol))
    return obj


def nubis_material(vol, extinction=0.04, g=0.33):
    """The cloud as Atlas's renderer has it without the noise up-rez (docs/render.md): inside the SDF,
    density = (dimensional profile x density scale) ^ (0.3 + 0.3 density_scale^4), extinction per metre
    = `extinction` x density, pure white scattering with one Henyey-Greenstein lobe of Atlas's mean
    cosine (what `atlas preview --artistic off` draws). With the lights of "Atlas Camera & Light" and
    enough volume bounces Cycles draws the cloud as `atlas preview --reference --artistic off --noise
    none` does (tests/blender/addon_test.py compares them)."""
    names = {g_.name for g_ in vol.grids}
    mat = bpy.data.materials.get("Atlas Nubis") or bpy.data.materials.new("Atlas Nubis")
    mat.use_nodes = True
    nt = mat.node_tree
    nt.nodes.clear()

    def attr(name):
        a_ = nt.nodes.new("ShaderNodeAttribute")
        a_.attribute_name = name
        return a_.outputs["Fac"]

    def node_math(op, x, y):
        m = nt.nodes.new("ShaderNodeMath")
        m.operation = op
        for i, v in enumerate((x, y)):
            if isinstance(v, (int, float)):
                m.inputs[i].default_value = v
            else:
                nt.links.new(v, m.inputs[i])
        return m.outputs[0]

    out = nt.nodes.new("ShaderNodeOutputMaterial")
    scatter = nt.nodes.new("ShaderNodeVolumeScatter")
    scatter.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
    scatter.inputs["Anisotropy"].default_value = g
    profile = "dimensional_profile" if "dimensional_profile" in names else sorted(names)[0] if names else "density"
    density = node_math("MAXIMUM", node_math("MINIMUM", attr(profile), 1.0), 0.0)
    if "density_scale" in names:
        scale = node_math("MAXIMUM", attr("density_scale"), 0.0)
        d = node_math("MULTIPLY", density, scale)
        s4 = node_math("POWER", node_math("MINIMUM", scale, 1.0), 4.0)
        density = node_math("POWER", d, node_math("ADD", node_math("MULTIPLY", s4, 0.3), 0.3))
    if "sdf" in names:
        density = node_math("MULTIPLY", density, node_math("LESS_THAN", attr("sdf"), 0.0))
    nt.links.new(node_math("MULTIPLY", density, extinction), scatter.inputs["Density"])
    nt.links.new(scatter.outputs["Volume"], out.inputs["Volume"])
    return mat


def setup_camera_and_light(scene):
    """A camera, sun and sky as `atlas preview` has them for the scene's graph (its default view and
    look, from Session.preview_settings), and Cycles' volume bounces raised for thick clouds."""
    session = _scene_state(scene)["session"]
    if session is None:
        raise RuntimeError("open a graph first")
    from mathutils import Vector

    st = session.preview_settings({"artistic": "off"}, noise="none")
    c = st["camera"]
    cam = bpy.data.objects.get("Atlas Camera")
    if cam is None:
        cam = bpy.data.objects.new("Atlas Camera", bpy.data.cameras.new("Atlas Camera"))
        scene.collection.objects.link(cam)
    cam.data.sensor_fit = "VERTICAL"
    cam.data.sensor_height = 24.0
    cam.data.lens = 0.5 * 24.0 / math.tan(math.radians(0.5 * c["fov_y_deg"]))
    cam.data.clip_start, cam.data.clip_end = 0.05, 1e7
    pos, look = Vector(c["position"]), Vector(c["look_at"])
    cam.location = pos
    cam.rotation_mode = "QUATERNION"
    cam.rotation_quaternion = (look - pos).normalized().to_track_quat("-Z", "Y")
    scene.camera = cam
    irr = st["sun"]["irradiance_rgb"]
    sun = bpy.data.objects.get("Atlas Sun")
    if sun is None:
        sun = bpy.data.objects.new("Atlas Sun", bpy.data.lights.new("Atlas Sun", type="SUN"))
        scene.collection.objects.link(sun)
    sun.data.energy = max(irr)
    sun.data.color = [v / max(irr) for v in irr]
    sun.data.angle = 0.0
    sun.rotation_mode = "QUATERNION"
    sun.rotation_quaternion = Vector(st["sun"]["direction_to_sun"]).normalized().to_track_quat("Z", "Y")
    world = bpy.data.worlds.get("Atlas Sky") or bpy.data.worlds.new("Atlas Sky")
    scene.world = world
    world.use_nodes = True
    nt = world.node_tree
    nt.nodes.clear()
    bg = nt.nodes.new("ShaderNodeBackground")
    out = nt.nodes.new("ShaderNodeOutputWorld")
    nt.links.new(bg.outputs["Background"], out.inputs["Surface"])
    tc, sep = nt.nodes.new("ShaderNodeTexCoord"), nt.nodes.new("ShaderNodeSeparateXYZ")
    clamp, mix = nt.nodes.new("ShaderNodeClamp"), nt.nodes.new("ShaderNodeMixRGB")
    nt.links.new(tc.outputs["Generated"], sep.inputs[0])
    nt.links.new(sep.outputs["Z"], clamp.inputs["Value"])
    nt.links.new(clamp.outputs[0], mix.inputs["Fac"])
    mix.inputs["Color1"].default_value = (*st["sky"]["horizon_rgb"], 1)
    mix.inputs["Color2"].default_value = (*st["sky"]["zenith_rgb"], 1)
    nt.links.new(mix.outputs["Color"], bg.inputs["Color"])
    # Thick clouds are white by multiple scattering: Blender's default of no volume bounces draws
    # them as dark smudges.
    scene.cycles.volume_bounces = max(scene.cycles.volume_bounces, 128)
    scene.cycles.max_bounces = max(scene.cycles.max_bounces, 128)
    # Cycles marches a heterogeneous volume in steps of a voxel x this rate, shadows included:
    # a step of a whole voxel through a dense cloud skips self-shadowing (measured: 21% too bright).
    scene.cycles.volume_step_rate = min(scene.cycles.volume_step_rate, 0.25)
    ph = st["phase"]
    g = ph["forward_weight"] * ph["g_forward"] + (1 - ph["forward_weight"]) * ph["g_back"]
    for vol in bpy.data.volumes:
        if vol.name.startswith("atlas_") and vol.materials:
            nubis_material(vol, st["extinction_per_metre"], g)
    return cam, sun


# ---------------------------------------------------------------- operators and panel


class ATLAS_OT_open_graph(bpy.types.Operator):
    bl_idname = "atlas.open_graph"
    bl_label = "Open Graph"
    bl_description = "Load an Atlas graph file and list its parameters"
    filepath: StringProperty(subtype="FILE_PATH")
    filter_glob: StringProperty(default="*.yaml;*.yml", options={"HIDDEN"})

    def invoke(self, context, event):
        context.window_manager.fileselect_add(self)
        return {"RUNNING_MODAL"}

    def execute(self, context):
        try:
            open_graph(context.scene, self.filepath or context.scene.atlas.graph_path)
        except Exception as e:
            context.scene.atlas.error = str(e)
            self.report({"ERROR"}, str(e))
            return {"CANCELLED"}
        return {"FINISHED"}


class ATLAS_OT_cook(bpy.types.Operator):
    bl_idname = "atlas.cook"
    bl_label = "Cook"
    bl_description = "Cook the graph (only what changed) and load its outputs"
    background: BoolProperty(default=True, description="Cook in a background thread")

    def execute(self, context):
        try:
            start_cook(context.scene, background=self.background and not bpy.app.background)
        except Exception as e:
            self.report({"ERROR"}, str(e))
            return {"CANCELLED"}
        if context.scene.atlas.error:
            self.report({"ERROR"}, context.scene.atlas.error)
            return {"CANCELLED"}
        return {"FINISHED"}


class ATLAS_OT_cancel(bpy.types.Operator):
    bl_idname = "atlas.cancel"
    bl_label = "Cancel"
    bl_description = "Stop the running cook (nothing is written)"

    def execute(self, context):
        job = _scene_state(context.scene)["job"]
        if job is not None:
            job.cancel.set()
        return {"FINISHED"}


class ATLAS_OT_param_info(bpy.types.Operator):
    bl_idname = "atlas.param_info"
    bl_label = ""
    node: StringProperty()
    param: StringProperty()

    @classmethod
    def description(cls, context, properties):
        for p in context.scene.atlas.params:
            if p.node == properties.node and p.name == properties.param:
                extra = " ".join(x for x in (p.range_text, p.unit) if x)
                choices = f" One of: {p.choices}." if p.choices else ""
                return f"{p.node}.{p.name} ({p.ptype}{', ' + extra if extra else ''}): {p.doc}{choices}"
        return ""

    def execute(self, context):
        return {"FINISHED"}


class ATLAS_PT_panel(bpy.types.Panel):
    bl_label = "Atlas"
    bl_idname = "ATLAS_PT_panel"
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "Atlas"

    def draw(self, context):
        props = context.scene.atlas
        layout = self.layout
        row = layout.row(align=True)
        row.prop(props, "graph_path", text="")
        row.operator("atlas.open_graph", text="", icon="FILE_FOLDER")
        layout.prop(props, "out_dir")
        row = layout.row(align=True)
        row.operator("atlas.cook", icon="PLAY")
        job = _scene_state(context.scene)["job"]
        if job is not None and not job.done():
            row.operator("atlas.cancel", icon="CANCEL")
        row = layout.row()
        row.prop(props, "auto_cook")
        row.prop(props, "jobs")
        row = layout.row()
        row.prop(props, "proxy")
        row.prop(props, "show_preview")
        layout.operator("atlas.camera_and_light", icon="LIGHT_SUN")
        if props.status:
            layout.label(text=props.status, icon="INFO")
        if props.error:
            box = layout.box()
            for line in props.error.splitlines()[:6]:
                box.label(text=line, icon="ERROR")
        layout.prop(props, "show_all")
        node = None
        box = None
        for p in props.params:
            if not props.show_all and not p.get("explicit", False):
                continue
            if p.node != node:
                node = p.node
                box = layout.box()
                box.label(text=node, icon="NODE")
            row = box.row(align=True)
            label = p.name + (f" ({p.unit})" if p.unit else "")
            vector = "iv" if p.ptype.startswith("int") else "v"
            field = {"float": "f", "int": "i", "bool": "b"}.get(p.ptype, vector if p.ptype in _VECTOR_TYPES else "s")
            row.prop(p, field, text=label)
            if p.name == "spheres" and p.ptype == "string":
                edit = row.operator("atlas.edit_spheres", text="", icon="SPHERE")
                edit.node, edit.param = p.node, p.name
            if p.node_type in _OBJECT_FILE_NODES and p.ptype == "path":
                bind = row.operator("atlas.bind_object", text="", icon="OBJECT_DATA")
                bind.node, bind.param = p.node, p.name
            info = row.operator("atlas.param_info", text="", icon="QUESTION")
            info.node, info.param = p.node, p.name


class ATLAS_PT_scene_panel(bpy.types.Panel):
    """The same panel in Properties > Scene."""
    bl_label = "Atlas"
    bl_idname = "ATLAS_PT_scene_panel"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "scene"
    bl_order = -100
    draw = ATLAS_PT_panel.draw


# ---------------------------------------------------------------- spheres as Blender objects
# A 'spheres' parameter ("x y z radius; ...", metres: volume/metaballs, volume/billows) can be edited in
# the viewport: each sphere becomes an Empty (display: sphere, size: the radius) in a collection named
# after the parameter; moving, scaling, duplicating or deleting them rewrites the parameter, which
# re-cooks the view like any edit.

_SPHERES_KEY = "atlas_spheres"  # collection property: "node.param"


def _parse_spheres(text):
    spheres = []
    for item in text.replace("\n", " ").split(";"):
        parts = item.split()
        if len(parts) == 4:
            spheres.append(tuple(float(x) for x in parts))
    return spheres


def _spheres_text(objects):
    def num(x):
        return f"{x:.6g}"
    return "; ".join(" ".join(num(v) for v in (o.location.x, o.location.y, o.location.z,
                                                o.empty_display_size * max(abs(c) for c in o.scale))) for o in objects)


def make_sphere_objects(scene, node, param):
    """Empties for the spheres of NODE.PARAM, in a collection of their own (replaced if it exists)."""
    item = next(p for p in scene.atlas.params if (p.node, p.name) == (node, param))
    name = f"atlas {node}.{param}"
    coll = bpy.data.collections.get(name)
    if coll is None:
        coll = bpy.data.collections.new(name)
        scene.collection.children.link(coll)
    for o in list(coll.objects):
        bpy.data.objects.remove(o)
    coll[_SPHERES_KEY] = f"{node}.{param}"
    for i, (x, y, z, r) in enumerate(_parse_spheres(item.s)):
        o = bpy.data.objects.new(f"{node}.{param}.{i:03d}", None)
        o.empty_display_type = "SPHERE"
        o.empty_display_size = r
        o.location = (x, y, z)
        coll.objects.link(o)
    return coll


def sync_sphere_objects(scene):
    """Writes each sphere collection back into its parameter when the objects changed (a move,
    scale, duplicate or delete). Called after every depsgraph update; returns the parameters set."""
    changed = []
    props = getattr(scene, "atlas", None)
    if props is None or _scene_state(scene)["session"] is None:
        return changed
    for coll in bpy.data.collections:
        key = coll.get(_SPHERES_KEY)
        if not key:
            continue
        node, param = key.split(".", 1)
        item = next((p for p in props.params if (p.node, p.name) == (node, param)), None)
        if item is None:
            continue
        objects = sorted((o for o in coll.objects if o.type == "EMPTY"), key=lambda o: o.name)
        text = _spheres_text(objects)
        if _parse_spheres(text) != [tuple(float(f"{v:.6g}") for v in sp) for sp in _parse_spheres(item.s)]:
            item.s = text  # the update re-cooks the view, or shows the library's message
            changed.append(key)
    return changed


@bpy.app.handlers.persistent
def _on_depsgraph(scene, depsgraph=None):
    if getattr(_on_depsgraph, "busy", False):
        return
    _on_depsgraph.busy = True
    try:
        sync_sphere_objects(scene)
        sync_object_files(scene)
    finally:
        _on_depsgraph.busy = False


class ATLAS_OT_edit_spheres(bpy.types.Operator):
    bl_idname = "atlas.edit_spheres"
    bl_label = "Edit in Viewport"
    bl_description = "Make the spheres Empties you can move, scale, duplicate or delete; the parameter follows"
    node: StringProperty()
    param: StringProperty()

    def execute(self, context):
        try:
            make_sphere_objects(context.scene, self.node, self.param)
        except Exception as e:
            self.report({"ERROR"}, str(e))
            return {"CANCELLED"}
        return {"FINISHED"}



# ---------------------------------------------------------------- meshes and points from Blender objects
# The file parameter of volume/read_mesh or volume/read_points can follow a Blender object: the
# object (its evaluated mesh in world space, metres) is written to a new file in the add-on's
# scratch folder whenever it changes (a move, a scale, an edit of its vertices), and the parameter
# is set to it, which re-cooks the view. read_points takes the vertices, with a 'radius' float
# attribute when the mesh has one (else the object's 'atlas_radius', 50 m).

_OBJECT_FILE_NODES = {"volume/read_mesh": "obj", "volume/read_points": "xyz"}
_BIND_KEY = "atlas_file_for"  # object property: "node.param"


def _object_geometry(obj):
    depsgraph = bpy.context.evaluated_depsgraph_get()
    ev = obj.evaluated_get(depsgraph)
    mesh = ev.to_mesh()
    try:
        m = obj.matrix_world
        verts = [tuple(m @ v.co) for v in mesh.vertices]
        mesh.calc_loop_triangles()
        tris = [tuple(t.vertices) for t in mesh.loop_triangles]
        radius = None
        attr = mesh.attributes.get("radius")
        if attr is not None and attr.domain == "POINT" and attr.data_type == "FLOAT":
            radius = [d.value for d in attr.data]
    finally:
        ev.to_mesh_clear()
    return verts, tris, radius


def _write_object_file(obj, geometry, path, kind):
    verts, tris, radius = geometry
    with open(path + ".tmp", "w") as f:
        if kind == "obj":
            f.writelines(f"v {x:.6g} {y:.6g} {z:.6g}\n" for x, y, z in verts)
            f.writelines(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in tris)
        else:
            r0 = float(obj.get("atlas_radius", 50.0))
            for i, (x, y, z) in enumerate(verts):
                f.write(f"{x:.6g} {y:.6g} {z:.6g} {radius[i] if radius else r0:.6g}\n")
    os.replace(path + ".tmp", path)


def bind_object(scene, obj, node, param):
    """Makes NODE.PARAM (a read_mesh / read_points file) follow `obj`; writes it once now."""
    obj[_BIND_KEY] = f"{node}.{param}"
    obj["atlas_signature"] = ""
    return sync_object_files(scene)


def _signature(geometry):
    verts, tris, radius = geometry
    return repr((len(verts), len(tris), [round(c, 4) for v in verts[:64] for c in v], round(sum(sum(v) for v in verts), 3),
                 None if radius is None else round(sum(radius), 3)))


def sync_object_files(scene):
    """Writes each bound object whose geometry or placement changed and points its parameter at the
    new file. Returns the parameters set."""
    changed = []
    props = getattr(scene, "atlas", None)
    if props is None or _scene_state(scene)["session"] is None:
        return changed
    for obj in scene.objects:
        key = obj.get(_BIND_KEY)
        if not key or obj.type != "MESH":
            continue
        node, param = key.split(".", 1)
        item = next((p for p in props.params if (p.node, p.name) == (node, param)), None)
        kind = _OBJECT_FILE_NODES.get(item.node_type) if item is not None else None
        if kind is None:
            continue
        geometry = _object_geometry(obj)  # evaluated once: compared, then written when it changed
        sig = _signature(geometry)
        if obj.get("atlas_signature") == sig:
            continue
        obj["atlas_signature"] = sig
        path = os.path.join(_scratch_dir(scene), f"{node}.{param}.{_next_serial(scene)}.{kind}")
        _write_object_file(obj, geometry, path, kind)
        old = item.s
        item.s = path  # the update re-cooks the view, or shows the library's message
        if old.startswith(_scratch_dir(scene)) and old != path and os.path.exists(old):
            os.remove(old)
        changed.append(key)
    return changed


class ATLAS_OT_bind_object(bpy.types.Operator):
    bl_idname = "atlas.bind_object"
    bl_label = "Use Active Object"
    bl_description = "Make this file follow the active mesh object: moving or editing it re-cooks"
    node: StringProperty()
    param: StringProperty()

    def execute(self, context):
        obj = context.view_layer.objects.active
        if obj is None or obj.type != "MESH":
            self.report({"ERROR"}, "select a mesh object first")
            return {"CANCELLED"}
        bind_object(context.scene, obj, self.node, self.param)
        return {"FINISHED"}


class ATLAS_OT_camera_and_light(bpy.types.Operator):
    bl_idname = "atlas.camera_and_light"
    bl_label = "Atlas Camera & Light"
    bl_description = "A camera, sun and sky as atlas preview has them, and enough volume bounces for Cycles to draw white clouds"

    def execute(self, context):
        try:
            setup_camera_and_light(context.scene)
        except Exception as e:
            self.report({"ERROR"}, str(e))
            return {"CANCELLED"}
        return {"FINISHED"}


_classes = (AtlasParam, AtlasSceneProps, AtlasPreferences, ATLAS_OT_open_graph, ATLAS_OT_cook, ATLAS_OT_cancel,
            ATLAS_OT_param_info, ATLAS_OT_edit_spheres, ATLAS_OT_bind_object, ATLAS_OT_camera_and_light, ATLAS_PT_panel, ATLAS_PT_scene_panel)


def register():
    for c in _classes:
        bpy.utils.register_class(c)
    bpy.types.Scene.atlas = PointerProperty(type=AtlasSceneProps)
    bpy.app.handlers.depsgraph_update_post.append(_on_depsgraph)


def unregister():
    for job in [s["job"] for s in _state.values() if s["job"] is not None]:
        job.cancel.set()
    if _on_depsgraph in bpy.app.handlers.depsgraph_update_post:
        bpy.app.handlers.depsgraph_update_post.remove(_on_depsgraph)
    del bpy.types.Scene.atlas
    for c in reversed(_classes):
        bpy.utils.unregister_class(c)
    _state.clear()

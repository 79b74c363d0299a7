"""Makes docs/images/blender_panel.png: Blender (with a window, e.g. under Xvfb) with the add-on's
panel after cooking the quickstart.

    blender -b --factory-startup --python-expr "import bpy; bpy.ops.wm.save_as_mainfile(filepath='/tmp/empty.blend')"
    xvfb-run -s "-screen 0 1600x900x24" blender /tmp/empty.blend --python plugins/blender/screenshot.py -- \
        --atlas-python build/python --graph examples/quickstart.yaml --out docs/images/blender_panel.png

(Opening a .blend file keeps the first-run splash screen away.)
"""
import argparse
import os
import sys
import tempfile

import bpy

args = argparse.ArgumentParser()
for a in ("--atlas-python", "--graph", "--out"):
    args.add_argument(a, required=True)
args = args.parse_args(sys.argv[sys.argv.index("--") + 1:])

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__))))
os.environ["ATLAS_PYTHONPATH"] = os.path.abspath(args.atlas_python)
import atlas_blender  # noqa: E402

atlas_blender.register()
scene = bpy.context.scene
for o in list(bpy.data.objects):  # the default cube
    if o.type == "MESH":
        bpy.data.objects.remove(o)
scene.atlas.out_dir = tempfile.mkdtemp(prefix="atlas_shot_")
scene.atlas.auto_cook = False
atlas_blender.open_graph(scene, os.path.abspath(args.graph))
atlas_blender.start_cook(scene, background=False)
# An edit as an artist makes it: the view at proxy 2 with Atlas's preview (Re-cook on change shown on).
scene.atlas.proxy = 2
for p in scene.atlas.params:
    if (p.node, p.name) == ("coverage", "in_min"):
        p.f = 0.45  # 0.5 makes the BC4 output's 0.05 bound unreachable (the cook fails)
atlas_blender.start_cook(scene, background=False, view=True)
scene.atlas.auto_cook = True


def _split(win, area, direction, factor):
    """Splits `area`; returns the new area."""
    before = set(win.screen.areas[:])
    region = next(r for r in area.regions if r.type == "WINDOW")
    with bpy.context.temp_override(window=win, screen=win.screen, area=area, region=region):
        bpy.ops.screen.area_split(direction=direction, factor=factor)
    return next(a for a in win.screen.areas if a not in before)


def shoot():
    win = bpy.context.window_manager.windows[0]
    view = next(a for a in win.screen.areas if a.type == "VIEW_3D")
    other = _split(win, view, "VERTICAL", 0.58)
    left, right = sorted((view, other), key=lambda a: a.x)
    right.type = "PROPERTIES"
    # Below the viewport, Atlas's preview of the last edit (the image 'atlas_preview').
    other = _split(win, left, "HORIZONTAL", 0.45)
    low, high = sorted((left, other), key=lambda a: a.y)
    high.type = "VIEW_3D"
    low.type = "IMAGE_EDITOR"
    low.spaces.active.image = bpy.data.images.get("atlas_preview")
    for area in win.screen.areas:
        area.tag_redraw()
    return None


def arrange():
    win = bpy.context.window_manager.windows[0]
    for area in sorted(win.screen.areas, key=lambda a: a.type != "VIEW_3D"):  # the view first: it selects
        if area.type == "PROPERTIES":
            # The tabs a Properties editor offers depend on its context: set it from inside.
            try:
                with bpy.context.temp_override(window=win, screen=win.screen, area=area):
                    area.spaces.active.context = "SCENE"
            except TypeError:
                pass  # an editor that has not been drawn yet offers no tabs; a new one opens on Scene
        if area.type == "IMAGE_EDITOR":
            region = next(r for r in area.regions if r.type == "WINDOW")
            with bpy.context.temp_override(window=win, screen=win.screen, area=area, region=region):
                bpy.ops.image.view_all(fit_view=True)
        if area.type == "VIEW_3D":
            space = area.spaces.active
            space.shading.type = "SOLID"
            space.clip_end = 50000
            space.show_region_ui = False
            vol = bpy.data.objects["atlas_nvdf"]
            for o in bpy.data.objects:
                o.select_set(o == vol)
            bpy.context.view_layer.objects.active = vol
            region = next(r for r in area.regions if r.type == "WINDOW")
            with bpy.context.temp_override(window=win, screen=win.screen, area=area, region=region):
                bpy.ops.view3d.view_selected()
        area.tag_redraw()
    return None


def show_scene_tab():
    win = bpy.context.window_manager.windows[0]
    for area in win.screen.areas:
        if area.type == "PROPERTIES":
            with bpy.context.temp_override(window=win, screen=win.screen, area=area):
                area.spaces.active.context = "SCENE"
            area.tag_redraw()
    return None


def save_and_quit():
    win = bpy.context.window_manager.windows[0]
    with bpy.context.temp_override(window=win, screen=win.screen, area=win.screen.areas[0]):
        bpy.ops.screen.screenshot(filepath=os.path.abspath(args.out))
    bpy.ops.wm.quit_blender()
    return None


bpy.app.timers.register(shoot, first_interval=0.5)
bpy.app.timers.register(arrange, first_interval=1.5)
bpy.app.timers.register(show_scene_tab, first_interval=3.0)
bpy.app.timers.register(save_and_quit, first_interval=6.0)

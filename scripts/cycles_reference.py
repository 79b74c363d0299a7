"""Render an Atlas scene export (atlas preview ... --export-scene DIR) with Blender's Cycles.

    blender -b --factory-startup --python scripts/cycles_reference.py -- DIR OUT.exr [options]

Options (after the "--"):
    --samples N        samples per pixel (default 1024)
    --bounces N        volume bounces (default 1024: thick clouds need hundreds, at 128 the superstorm
                       lost 5.5% of its light; 0 = single scattering of sun and sky)
    --step-rate R      Cycles volume step rate (voxel sizes per step, default 0.5)
    --seed S           Cycles seed (default 0)
    --sun-scale K      multiply the sun irradiance by K (tests use K != 1 to prove they can fail)
    --no-sky           black sky (isolates the sun term)
    --size WxH         override the exported image size
    --threads N        render threads (default 0 = all)
    --alpha            transparent film: the EXR's A channel is 1 - the view ray's transmittance
    --stats FILE       write {"seconds": wall, "cpu_seconds": process CPU, "samples": N} as JSON

What is matched (docs/render.md, "Reference: Cycles"):
    density     DIR/density.vdb grid "density" in world metres (Atlas's density, sampled at twice
                the scene resolution); extinction = extinction_per_metre x density, albedo 1
    phase       one Henyey-Greenstein lobe (a Volume Scatter closure); atlas preview --artistic off
                replaces the dual lobe by one with its mean cosine. A dual lobe is refused: Cycles 3.4
                adds two scatter closures' phase functions without weighting them (measured)
    sun         a Sun light of angle 0 whose irradiance is 4 pi x Atlas's sun colour (Atlas's phase
                function is normalised to 1 for isotropic scattering, i.e. 4 pi x the 1/sr phase)
    sky         the world colour lerp(horizon, zenith, saturate(dir.z)) (radiance as in Atlas)
    camera      Atlas's pinhole: vertical field of view, pixel-centre rays (filter width 0.01 px),
                clip end raised far beyond the 100 m default (the VDB keeps its metres)
    output      linear scene radiance EXR (no view transform, exposure 0), no denoising (Debian's
                Blender has no OpenImageDenoise), no sample clamping
"""

import json
import math
import os
import sys
import time

import bpy
from mathutils import Vector


def parse(argv):
    args = argv[argv.index("--") + 1:] if "--" in argv else []
    if len(args) < 2:
        raise SystemExit("usage: blender -b --python cycles_reference.py -- DIR OUT.exr [options]")
    o = {"dir": args[0], "out": args[1], "samples": 1024, "bounces": 1024, "step_rate": 0.5, "seed": 0, "sun_scale": 1.0,
         "sky": True, "alpha": False, "size": None, "threads": 0, "stats": None}
    i = 2
    while i < len(args):
        a = args[i]
        if a in ("--no-sky", "--alpha"):
            o["sky" if a == "--no-sky" else "alpha"] = a == "--alpha"
            i += 1
            continue
        if i + 1 >= len(args):
            raise SystemExit(f"{a} needs a value")
        v = args[i + 1]
        if a == "--samples": o["samples"] = int(v)
        elif a == "--bounces": o["bounces"] = int(v)
        elif a == "--step-rate": o["step_rate"] = float(v)
        elif a == "--seed": o["seed"] = int(v)
        elif a == "--sun-scale": o["sun_scale"] = float(v)
        elif a == "--size": o["size"] = tuple(int(x) for x in v.split("x"))
        elif a == "--threads": o["threads"] = int(v)
        elif a == "--stats": o["stats"] = v
        else: raise SystemExit(f"unknown option {a}")
        i += 2
    return o


def build(o):
    with open(os.path.join(o["dir"], "scene.json")) as f:
        sc = json.load(f)
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene

    # Render settings: unbiased, unclamped, undenoised, linear.
    scene.render.engine = "CYCLES"
    cy = scene.cycles
    cy.device = "CPU"
    cy.samples = o["samples"]
    cy.use_adaptive_sampling = False
    cy.use_denoising = False
    cy.seed = o["seed"]
    cy.max_bounces = max(o["bounces"], 1)
    cy.volume_bounces = o["bounces"]
    cy.transparent_max_bounces = max(o["bounces"], 8)
    cy.diffuse_bounces = cy.glossy_bounces = cy.transmission_bounces = 0
    cy.sample_clamp_direct = 0.0
    cy.sample_clamp_indirect = 0.0
    cy.volume_step_rate = o["step_rate"]
    cy.volume_max_steps = 4096
    cy.filter_width = 0.01  # Atlas shoots one ray through each pixel centre
    cy.caustics_reflective = cy.caustics_refractive = True
    cy.blur_glossy = 0.0
    cy.film_exposure = 1.0
    w, h = o["size"] or (sc["width"], sc["height"])
    scene.render.resolution_x, scene.render.resolution_y, scene.render.resolution_percentage = w, h, 100
    scene.render.film_transparent = o["alpha"]
    scene.render.threads_mode = "FIXED" if o["threads"] > 0 else "AUTO"
    if o["threads"] > 0:
        scene.render.threads = o["threads"]
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = "32"
    scene.render.image_settings.color_mode = "RGBA" if o["alpha"] else "RGB"
    scene.render.image_settings.exr_codec = "ZIP"

    # Camera: Atlas's pinhole (vertical fov, up = world z).
    c = sc["camera"]
    cam_data = bpy.data.cameras.new("atlas_camera")
    cam_data.sensor_fit = "VERTICAL"
    cam_data.sensor_height = 24.0
    cam_data.lens = 0.5 * cam_data.sensor_height / math.tan(0.5 * math.radians(c["fov_y_deg"]))
    cam_data.clip_start = 0.05
    cam_data.clip_end = 1e7
    cam = bpy.data.objects.new("atlas_camera", cam_data)
    scene.collection.objects.link(cam)
    pos, look = Vector(c["position"]), Vector(c["look_at"])
    cam.location = pos
    cam.rotation_mode = "QUATERNION"
    cam.rotation_quaternion = (look - pos).normalized().to_track_quat("-Z", "Y")
    scene.camera = cam

    # Sun: a delta light (angle 0); it shines along -direction_to_sun.
    s = sc["sun"]
    irr = [v * o["sun_scale"] for v in s["irradiance_rgb"]]
    strength = max(irr)
    if strength > 0:
        sun_data = bpy.data.lights.new("atlas_sun", type="SUN")
        sun_data.energy = strength
        sun_data.color = [v / strength for v in irr]
        sun_data.angle = 0.0
        sun_data.cycles.cast_shadow = True
        sun = bpy.data.objects.new("atlas_sun", sun_data)
        sun.rotation_mode = "QUATERNION"
        sun.rotation_quaternion = Vector(s["direction_to_sun"]).normalized().to_track_quat("Z", "Y")
        scene.collection.objects.link(sun)

    # Sky: lerp(horizon, zenith, saturate(dir.z)); the world's Generated
    # coordinate is the unit view direction.
    world = bpy.data.worlds.new("atlas_sky")
    scene.world = world
    world.use_nodes = True
    nt = world.node_tree
    nt.nodes.clear()
    bg = nt.nodes.new("ShaderNodeBackground")
    outw = nt.nodes.new("ShaderNodeOutputWorld")
    nt.links.new(bg.outputs["Background"], outw.inputs["Surface"])
    bg.inputs["Strength"].default_value = 1.0
    zen, hor = sc["sky"]["zenith_rgb"], sc["sky"]["horizon_rgb"]
    if not o["sky"]:
        bg.inputs["Color"].default_value = (0, 0, 0, 1)
    elif zen == hor:
        bg.inputs["Color"].default_value = (*zen, 1)
    else:
        tc = nt.nodes.new("ShaderNodeTexCoord")
        sep = nt.nodes.new("ShaderNodeSeparateXYZ")
        clamp = nt.nodes.new("ShaderNodeClamp")
        mix = nt.nodes.new("ShaderNodeMixRGB")
        mix.blend_type = "MIX"
        nt.links.new(tc.outputs["Generated"], sep.inputs[0])
        nt.links.new(sep.outputs["Z"], clamp.inputs["Value"])
        nt.links.new(clamp.outputs[0], mix.inputs["Fac"])
        mix.inputs["Color1"].default_value = (*hor, 1)
        mix.inputs["Color2"].default_value = (*zen, 1)
        nt.links.new(mix.outputs["Color"], bg.inputs["Color"])

    # The cloud: two Volume Scatter lobes over the density grid.
    vol = bpy.data.volumes.new("atlas_density")
    vol.filepath = os.path.abspath(os.path.join(o["dir"], sc["density_file"]))
    if not vol.grids.load():
        raise RuntimeError(f"{vol.filepath}: {vol.grids.error_message}")
    vol.render.space = "WORLD"
    vol.render.step_size = 0.0  # automatic: one voxel x the scene's volume_step_rate
    obj = bpy.data.objects.new("atlas_density", vol)
    # Measured (a symmetric box, docs/render.md): Blender 3.4's Cycles draws a VDB half a voxel
    # toward +x, +y, +z of where its transform puts the voxel centres (0.37 px at 160x90, growing
    # with the image size, so not a pixel convention); moving the object back by half a voxel
    # puts the centres where Atlas has them.
    obj.location = [-0.5 * (hi - lo) / n for lo, hi, n in zip(sc["bounds_min"], sc["bounds_max"], sc["resolution"])]
    scene.collection.objects.link(obj)
    mat = bpy.data.materials.new("atlas_cloud")
    mat.use_nodes = True
    mt = mat.node_tree
    mt.nodes.clear()
    out = mt.nodes.new("ShaderNodeOutputMaterial")
    attr = mt.nodes.new("ShaderNodeAttribute")
    attr.attribute_name = sc["density_grid"]
    ph = sc["phase"]
    ext = sc["extinction_per_metre"]
    lobes = [(ph["forward_weight"], ph["g_forward"]), (1 - ph["forward_weight"], ph["g_back"])]
    if all(wt > 0 for wt, _ in lobes):
        # Measured (box test, docs/render.md): Cycles 3.4 adds the phase functions of two
        # Volume Scatter closures without weighting them by their densities (Add and Mix
        # Shader alike), so a dual lobe would be drawn as HG(g1) + HG(g2).
        raise SystemExit("the scene has a dual-lobe phase function; Cycles 3.4 cannot draw one (export with --artistic off: one lobe)")
    shaders = []
    for weight, g in lobes:
        if weight <= 0:
            continue
        mul = mt.nodes.new("ShaderNodeMath")
        mul.operation = "MULTIPLY"
        mul.inputs[1].default_value = ext * weight
        mt.links.new(attr.outputs["Fac"], mul.inputs[0])
        sc_node = mt.nodes.new("ShaderNodeVolumeScatter")
        sc_node.inputs["Color"].default_value = (1, 1, 1, 1)
        sc_node.inputs["Anisotropy"].default_value = g
        mt.links.new(mul.outputs[0], sc_node.inputs["Density"])
        shaders.append(sc_node.outputs[0])
    vol_out = shaders[0]
    for extra in shaders[1:]:
        add = mt.nodes.new("ShaderNodeAddShader")
        mt.links.new(vol_out, add.inputs[0])
        mt.links.new(extra, add.inputs[1])
        vol_out = add.outputs[0]
    mt.links.new(vol_out, out.inputs["Volume"])
    vol.materials.append(mat)
    return scene


def main():
    o = parse(sys.argv)
    scene = build(o)
    scene.render.filepath = os.path.abspath(o["out"])
    t0, c0 = time.perf_counter(), time.process_time()
    bpy.ops.render.render(write_still=True)
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    if o["stats"]:
        with open(o["stats"], "w") as f:
            json.dump({"seconds": wall, "cpu_seconds": cpu, "samples": o["samples"], "bounces": o["bounces"]}, f)
    print(f"cycles_reference: {o['out']} ({o['samples']} samples, {o['bounces']} volume bounces) in {wall:.2f} s, {cpu:.2f} s CPU")


try:
    main()
except SystemExit as e:
    print(f"cycles_reference: {e}", file=sys.stderr)
    sys.exit(2)
except Exception as e:  # a failed render must fail the blender process
    import traceback
    traceback.print_exc()
    sys.exit(1)

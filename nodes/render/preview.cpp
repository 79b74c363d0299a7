// render/preview: a Nubis³-style ray-marched picture of an NVDF set, an NDF
// set (2.5D) or both composited, so a graph can write a preview beside its
// textures (libatlas/render; the 2.5D scene and look are atlas preview's:
// atlas/render/preview.h).
#include "atlas/graph/node.h"
#include "atlas/render/image_out.h"
#include "atlas/render/layer.h"
#include "atlas/render/preview.h"
#include "atlas/render/renderer.h"

#include <cmath>
#include <optional>

namespace {
using namespace atlas;

void declare(NodeDeclaration& d) {
    d.doc("Renders the NVDF set (voxel mode) and/or the NDF set (2.5D mode, the cloud layer over a curved Earth) with the "
          "preview ray-marchers (docs/render.md), as `atlas preview` does: `image` is linear radiance r, g, b plus view "
          "transmittance (write it as EXR), `preview` the tone-mapped sRGB picture (write it as PNG). Give `nvdf` "
          "(volume/nvdf's vdb_set) or `modeling` and `sdf`, and/or `ndf`; with both, the voxel clouds are composited over "
          "the layer. 2.5D mode uses the CLI's daylight look (sky gradient, sun radiance 2.6; sun_colour and sky_* apply to "
          "voxel-only previews) and the camera presets of `view`.");
    d.input("nvdf", PortType::Field, "4 channels dimensional_profile, detail_type, density_scale, sdf (metres)").optional = true;
    d.input("modeling", PortType::Field, "modeling NVDF (dimensional_profile, detail_type, density_scale)").optional = true;
    d.input("sdf", PortType::Field, "signed distance in metres, same grid as modeling").optional = true;
    d.input("noise", PortType::Field, "Nubis noise volume, 4 channels in [0, 1], tiling (none: no up-rez)").optional = true;
    d.input("ndf", PortType::Field2D, "2.5D: an NDF set (coverage, min_height, max_height, ...) or a weather map (coverage [, type, precipitation])")
        .optional = true;
    d.input("profile_lut", PortType::Field2D, "2.5D: ndf/profile_lut (none: the default profile)").optional = true;
    d.input("base_noise", PortType::Field3D, "2.5D: noise/hzd_set low (none: smooth shapes)").optional = true;
    d.input("detail_noise", PortType::Field3D, "2.5D: noise/hzd_set high (none: no erosion)").optional = true;
    d.input("curl", PortType::Field2D, "2.5D: noise/hzd_set curl (none: no distortion)").optional = true;
    d.input("anvil", PortType::Field2D, "2.5D: ndf/superstorm_anvil map").optional = true;
    d.input("vortex_table", PortType::Field2D, "2.5D: ndf/vortex_rings table").optional = true;
    d.input("flash_probability", PortType::Field,
            "3D field (channel 0): per-voxel relative probability of a lightning flash; each flash places flash_count lights")
        .optional = true;
    d.output("image", PortType::Field, "linear r, g, b radiance and transmittance (2D)");
    d.output("preview", PortType::Field, "tone-mapped sRGB r, g, b in [0, 1] (2D)");
    d.param_int2("size", {{480, 270}}).range(1, 8192).with_unit("px").describe("image width and height");
    d.param_enum("camera", {"auto", "manual"}, "auto").describe("auto frames the whole volume from azimuth/elevation; manual uses position and look_at");
    d.param_float("azimuth", 30).range(-360, 360).with_unit("deg").describe("auto camera: direction around the volume (0 = from -y)");
    d.param_float("elevation", 20).range(-89, 89).with_unit("deg").describe("auto camera: height angle above the volume centre");
    d.param_float3("position", {{0, -1000, 100}}).with_unit("m").describe("manual camera position");
    d.param_float3("look_at", {{0, 0, 100}}).with_unit("m").describe("manual camera target");
    d.param_float("fov", 50).range(0.01, 179).with_unit("deg").describe("vertical field of view (voxel auto and manual cameras)");
    d.param_enum("view", {"orbit", "ground", "aerial"}, "orbit")
        .describe("2.5D auto camera: layer preset (orbit uses azimuth and elevation; ground and aerial as atlas preview --view)");
    d.param_float("time", 0).range(-1e9, 1e9).with_unit("s").describe("2.5D: wind scroll and vortex-ring turn time");
    d.param_float("sun_azimuth", render::kPreviewSunAzimuthDeg).range(-360, 360).with_unit("deg").describe("sun direction around the horizon (0 = from -y)");
    d.param_float("sun_elevation", render::kPreviewSunElevationDeg).range(-90, 90).with_unit("deg").describe("sun height above the horizon");
    d.param_float3("sun_colour", {{1.0, 0.95, 0.88}}).range(0, 1e6).describe("linear sun radiance");
    d.param_float3("sky_colour", {{0.30, 0.45, 0.75}}).range(0, 1e6).describe("linear sky radiance at the zenith (the whole sky when sky_horizon equals it)");
    d.param_float3("sky_horizon", {{0.30, 0.45, 0.75}})
        .range(0, 1e6)
        .describe("linear sky radiance at the horizon; differing from sky_colour makes a gradient (background and ambient)");
    d.param_string("lights", "").describe(
        "point lights as 'x,y,z,r,g,b,intensity[,radius]' (commas or spaces; metres, linear colour, inverse-square intensity, optional reach), "
        "separated by ';' (the syntax of atlas preview --light)");
    d.param_int("flash_seed", 1).range(0, 4294967295.0).describe("flash lights: seed of the position draws");
    d.param_int("flash_index", 0).range(-2147483648.0, 2147483647.0).describe("flash lights: which flash (time); each index draws new positions");
    d.param_int("flash_count", 1).range(0, 4096).describe("flash lights: lights per flash");
    d.param_float3("flash_colour", {{0.75, 0.8, 1.0}}).range(0, 1e6).describe("flash lights: linear colour");
    d.param_float("flash_intensity", 1e5).range(0, 1e12).describe("flash lights: intensity of each light (inverse square, metres)");
    d.param_float("flash_radius", 0).range(0, 1e9).with_unit("m").describe("flash lights: reach (0 = unlimited)");
    d.param_enum("mode", {"fast", "reference"}, "fast").describe("fast (SDF skipping, light grid) or reference (small fixed steps, marched light)");
    d.param_float("quality", 1).range(0.01, 64).describe("fast mode: step count scale (2 = half-length steps)");
    d.param_float("extinction", 0.04).range(0, 1e6).with_unit("1/m").describe("extinction at density 1");
    d.param_float("noise_tile", 256).range(1e-3, 1e9).with_unit("m").describe("metres per noise period");
    d.param_float("exposure", 1.5).range(1e-6, 1e6).describe("preview tone map: radiance multiplier before Reinhard and sRGB");
}

void cook(CookContext& ctx) {
    render::CloudScene scene;
    Field3DPtr noise = ctx.has_input("noise") ? ctx.input_field3d("noise") : nullptr;
    bool voxel = true;
    if (ctx.has_input("nvdf")) {
        scene = render::scene_from_nvdf_set(ctx.input_field3d("nvdf"), noise, ctx.get_float("noise_tile"));
    } else if (ctx.has_input("modeling") && ctx.has_input("sdf")) {
        scene = {ctx.input_field3d("modeling"), ctx.input_field3d("sdf"), noise, ctx.get_float("noise_tile")};
    } else if (ctx.has_input("ndf")) {
        voxel = false;
    } else {
        ctx.fail("connect 'nvdf', both 'modeling' and 'sdf', or 'ndf' (2.5D)");
    }
    std::optional<render::LayerScene> layer;
    if (ctx.has_input("ndf")) {
        // The same scene assembly as atlas preview (render::layer_preview_scene).
        render::LayerPreviewInputs in;
        in.ndf = ctx.input_field2d("ndf");
        if (!render::is_ndf_set(*in.ndf) && !render::is_weather_map(*in.ndf))
            ctx.fail("ndf: expected an NDF set (coverage, min_height, max_height) or a weather map (coverage)");
        if (ctx.has_input("profile_lut")) in.profile_lut = ctx.input_field2d("profile_lut");
        if (ctx.has_input("base_noise")) in.base_noise = ctx.input_field3d("base_noise");
        if (ctx.has_input("detail_noise")) in.detail_noise = ctx.input_field3d("detail_noise");
        if (ctx.has_input("curl")) in.curl = ctx.input_field2d("curl");
        if (ctx.has_input("anvil")) in.anvil = ctx.input_field2d("anvil");
        if (ctx.has_input("vortex_table")) in.vortex_table = ctx.input_field2d("vortex_table");
        layer = render::layer_preview_scene(in);
        layer->time = ctx.get_float("time");
    }
    const Vec2i size = ctx.get_int2("size");
    ctx.check_memory(uint64_t(size[0]) * uint64_t(size[1]) * 7 * sizeof(float) * (layer ? 2 : 1), "preview image");
    const double aspect = double(size[0]) / size[1];
    render::RenderSettings s;
    if (layer) {
        const std::string v = ctx.get_string("view");
        const auto kind = v == "ground" ? render::LayerView::Ground : v == "aerial" ? render::LayerView::Aerial : render::LayerView::Orbit;
        s = render::layer_preview_settings(*layer, size[0], size[1], kind, ctx.get_float("azimuth"), ctx.get_float("elevation"));
        if (ctx.get_string("camera") == "manual") {
            s.camera.position = ctx.get_float3("position");
            s.camera.look_at = ctx.get_float3("look_at");
            s.camera.fov_deg = ctx.get_float("fov");
        }
    } else {
        s = render::preview_settings(scene.modeling->bounds(), size[0], size[1]);
        if (ctx.get_string("camera") == "auto") {
            s.camera = render::framing_camera(scene.modeling->bounds(), aspect, ctx.get_float("azimuth"), ctx.get_float("elevation"), ctx.get_float("fov"));
        } else {
            s.camera.position = ctx.get_float3("position");
            s.camera.look_at = ctx.get_float3("look_at");
            s.camera.fov_deg = ctx.get_float("fov");
        }
        const Vec3d sun = ctx.get_float3("sun_colour"), sky = ctx.get_float3("sky_colour");
        s.sun_colour = {{float(sun[0]), float(sun[1]), float(sun[2])}};
        s.sky_colour = {{float(sky[0]), float(sky[1]), float(sky[2])}};
        const Vec3d horizon = ctx.get_float3("sky_horizon");
        if (!(horizon == sky)) s.sky_horizon = Vec3f{{float(horizon[0]), float(horizon[1]), float(horizon[2])}};
    }
    s.sun_direction = render::sun_direction(ctx.get_float("sun_azimuth"), ctx.get_float("sun_elevation"));
    try {
        s.lights = render::parse_point_lights(ctx.get_string("lights"));
    } catch (const Error& e) {
        ctx.fail(e.what());
    }
    if (ctx.has_input("flash_probability")) {
        render::LightField f;
        f.probability = ctx.input_field3d("flash_probability");
        const Vec3d fc = ctx.get_float3("flash_colour");
        f.colour = {{float(fc[0]), float(fc[1]), float(fc[2])}};
        f.intensity = ctx.get_float("flash_intensity");
        f.radius = ctx.get_float("flash_radius");
        f.seed = uint32_t(ctx.get_int("flash_seed"));
        f.flash = int32_t(ctx.get_int("flash_index"));
        f.count = int(ctx.get_int("flash_count"));
        s.light_fields.push_back(f);
    }
    s.mode = ctx.get_string("mode") == "reference" ? render::RenderMode::Reference : render::RenderMode::Fast;
    s.quality = ctx.get_float("quality");
    s.extinction = ctx.get_float("extinction");
    // Forwarded from render workers: the host's callbacks are thread-safe.
    ProgressSink sink;
    sink.on_progress = [&ctx](const ProgressEvent& e) { ctx.progress(e.fraction); };
    sink.is_cancelled = ctx.progress_sink().is_cancelled;
    std::optional<Field2D> image;
    if (layer) {
        auto r = render::render_layer(*layer, s, &sink);
        ctx.metric("full_samples", double(r.report.full_samples));
        ctx.metric("point_lights", double(r.report.point_lights));
        image = std::move(r.image);
    }
    if (voxel) {
        auto result = render::render_clouds(scene, s, &sink);
        ctx.metric("density_samples", double(result.report.density_samples));
        ctx.metric("billowy", result.report.billowy ? 1 : 0);
        ctx.metric("noise_uprez", result.report.noise_uprez ? 1 : 0);
        ctx.metric("point_lights", double(result.report.point_light_count));
        image = image ? render::composite_over(result.image, *image, s) : std::move(result.image);
    }
    auto preview = std::make_shared<Field2D>(render::tone_map(*image, ctx.get_float("exposure")));
    ctx.set_output("image", std::make_shared<Field2D>(std::move(*image)));
    ctx.set_output("preview", Field2DPtr(preview));
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "render/preview", .version = 2, .declare = declare, .cook = cook});
}

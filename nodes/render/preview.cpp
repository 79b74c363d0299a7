// render/preview: a Nubis³-style ray-marched picture of an NVDF set, so a
// graph can write a preview beside its textures (libatlas/render).
#include "atlas/graph/node.h"
#include "atlas/render/image_out.h"
#include "atlas/render/renderer.h"

#include <cmath>
#include <cstdlib>
#include <sstream>

namespace {
using namespace atlas;

void declare(NodeDeclaration& d) {
    d.doc("Renders the NVDF set with the preview ray-marcher (docs/render.md): `image` is linear radiance r, g, b plus "
          "view transmittance (write it as EXR), `preview` the tone-mapped sRGB picture (write it as PNG). Give either "
          "`nvdf` (volume/nvdf's vdb_set) or `modeling` and `sdf`.");
    d.input("nvdf", PortType::Field, "4 channels dimensional_profile, detail_type, density_scale, sdf (metres)").optional = true;
    d.input("modeling", PortType::Field, "modeling NVDF (dimensional_profile, detail_type, density_scale)").optional = true;
    d.input("sdf", PortType::Field, "signed distance in metres, same grid as modeling").optional = true;
    d.input("noise", PortType::Field, "Nubis noise volume, 4 channels in [0, 1], tiling (none: no up-rez)").optional = true;
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
    d.param_float("fov", 50).range(0.01, 179).with_unit("deg").describe("vertical field of view");
    d.param_float("sun_azimuth", 60).range(-360, 360).with_unit("deg").describe("sun direction around the horizon (0 = from -y)");
    d.param_float("sun_elevation", 35).range(-90, 90).with_unit("deg").describe("sun height above the horizon");
    d.param_float3("sun_colour", {{1.0, 0.95, 0.88}}).range(0, 1e6).describe("linear sun radiance");
    d.param_float3("sky_colour", {{0.30, 0.45, 0.75}}).range(0, 1e6).describe("linear sky radiance at the zenith (the whole sky when sky_horizon equals it)");
    d.param_float3("sky_horizon", {{0.30, 0.45, 0.75}})
        .range(0, 1e6)
        .describe("linear sky radiance at the horizon; differing from sky_colour makes a gradient (background and ambient)");
    d.param_string("lights", "").describe(
        "point lights as 'x y z r g b intensity [radius]' (metres, linear colour, inverse-square intensity, optional reach), separated by ';'");
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

std::vector<render::PointLight> parse_lights(CookContext& ctx) {
    std::vector<render::PointLight> lights;
    std::stringstream all(ctx.get_string("lights"));
    for (std::string item; std::getline(all, item, ';');) {
        std::stringstream one(item);
        std::vector<double> v;
        bool ok = true;
        for (std::string t; one >> t;) {
            char* end = nullptr;
            v.push_back(std::strtod(t.c_str(), &end));
            ok = ok && end != t.c_str() && *end == '\0' && std::isfinite(v.back());
        }
        if (v.empty() && ok) continue;
        if (!ok || (v.size() != 7 && v.size() != 8))
            ctx.fail("lights: expected 'x y z r g b intensity [radius]' (finite numbers) separated by ';', got '" + item + "'");
        render::PointLight l;
        l.position = {{v[0], v[1], v[2]}};
        l.colour = {{float(v[3]), float(v[4]), float(v[5])}};
        l.intensity = v[6];
        l.radius = v.size() == 8 ? v[7] : 0.0;
        lights.push_back(l);
    }
    return lights;
}

void cook(CookContext& ctx) {
    render::CloudScene scene;
    Field3DPtr noise = ctx.has_input("noise") ? ctx.input_field3d("noise") : nullptr;
    if (ctx.has_input("nvdf")) {
        scene = render::scene_from_nvdf_set(ctx.input_field3d("nvdf"), noise, ctx.get_float("noise_tile"));
    } else if (ctx.has_input("modeling") && ctx.has_input("sdf")) {
        scene = {ctx.input_field3d("modeling"), ctx.input_field3d("sdf"), noise, ctx.get_float("noise_tile")};
    } else {
        ctx.fail("connect either 'nvdf' or both 'modeling' and 'sdf'");
    }
    const Vec2i size = ctx.get_int2("size");
    ctx.check_memory(uint64_t(size[0]) * uint64_t(size[1]) * 7 * sizeof(float), "preview image");
    render::RenderSettings s = render::preview_settings(scene.modeling->bounds(), size[0], size[1]);
    if (ctx.get_string("camera") == "auto") {
        s.camera = render::framing_camera(scene.modeling->bounds(), double(size[0]) / size[1], ctx.get_float("azimuth"),
                                          ctx.get_float("elevation"), ctx.get_float("fov"));
    } else {
        s.camera.position = ctx.get_float3("position");
        s.camera.look_at = ctx.get_float3("look_at");
        s.camera.fov_deg = ctx.get_float("fov");
    }
    s.sun_direction = render::sun_direction(ctx.get_float("sun_azimuth"), ctx.get_float("sun_elevation"));
    const Vec3d sun = ctx.get_float3("sun_colour"), sky = ctx.get_float3("sky_colour");
    s.sun_colour = {{float(sun[0]), float(sun[1]), float(sun[2])}};
    s.sky_colour = {{float(sky[0]), float(sky[1]), float(sky[2])}};
    const Vec3d horizon = ctx.get_float3("sky_horizon");
    if (!(horizon == sky)) s.sky_horizon = Vec3f{{float(horizon[0]), float(horizon[1]), float(horizon[2])}};
    s.lights = parse_lights(ctx);
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
    auto result = render::render_clouds(scene, s, &sink);
    ctx.metric("density_samples", double(result.report.density_samples));
    ctx.metric("billowy", result.report.billowy ? 1 : 0);
    ctx.metric("noise_uprez", result.report.noise_uprez ? 1 : 0);
    ctx.metric("point_lights", double(result.report.point_light_count));
    auto preview = std::make_shared<Field2D>(render::tone_map(result.image, ctx.get_float("exposure")));
    ctx.set_output("image", std::make_shared<Field2D>(std::move(result.image)));
    ctx.set_output("preview", Field2DPtr(preview));
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "render/preview", .version = 1, .declare = declare, .cook = cook});
}

#include "export_scene.h"

#include "atlas/core/error.h"
#include "atlas/io/vdb.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <numbers>
#include <sstream>

namespace atlas::cli {

namespace {

std::string num(double v) {
    char b[40];
    std::snprintf(b, sizeof b, "%.9g", v);
    return b;
}

template <class V>
std::string vec3(const V& v) {
    return "[" + num(v[0]) + ", " + num(v[1]) + ", " + num(v[2]) + "]";
}

} // namespace

std::string export_scene(const std::filesystem::path& dir, render::CloudScene& scene, const render::RenderSettings& s) {
    if (!s.lights.empty() || !s.light_fields.empty()) throw Error("--export-scene: point lights and lightning are not exported (only sun and sky)");
    std::filesystem::create_directories(dir);
    std::string note;
    const Vec3i res = scene.modeling->resolution();
    if (scene.noise) {
        scene = render::density_scene(render::sample_density(scene, res));
        note = "the up-rez noise is baked into a " + std::to_string(res[0]) + "x" + std::to_string(res[1]) + "x" + std::to_string(res[2]) +
               " density grid, which the preview then draws; ";
    }
    Vec3i fine;
    for (int a = 0; a < 3; ++a) fine[a] = std::min(512, 2 * res[a]);
    Field3D density = render::sample_density(scene, fine);
    // Blender 3.4's Cycles draws a VDB's active tiles as empty (a uniform
    // 8^3 block that OpenVDB prunes into a tile vanishes): raise every other
    // non-zero voxel by one float ulp (1e-7 relative) so no block is uniform.
    for (int z = 0; z < fine[2]; ++z)
        for (int y = 0; y < fine[1]; ++y)
            for (int x = 0; x < fine[0]; ++x) {
                float& v = density.at(0, x, y, z);
                if (v > 0 && ((x + y + z) & 1)) v = std::nextafter(v, std::numeric_limits<float>::infinity());
            }
    io::write_vdb(density, dir / "density.vdb");

    // Atlas's phase function is normalised to 1 for isotropic scattering
    // (4 pi x the 1/sr phase), so its sun colour is the sun irradiance / (4 pi):
    // E = 4 pi sun_colour. Sky colours are radiance as they are.
    const Vec3d sun = s.sun_direction / length(s.sun_direction);
    const double four_pi = 4 * std::numbers::pi;
    const Vec3f horizon = s.sky_horizon.value_or(s.sky_colour);
    const Box3d b = density.bounds();
    std::ostringstream j;
    j << "{\n"
      << "  \"format\": \"atlas-cycles-scene 1\",\n"
      << "  \"density_file\": \"density.vdb\",\n"
      << "  \"density_grid\": \"density\",\n"
      << "  \"resolution\": [" << fine[0] << ", " << fine[1] << ", " << fine[2] << "],\n"
      << "  \"bounds_min\": " << vec3(b.min) << ",\n"
      << "  \"bounds_max\": " << vec3(b.max) << ",\n"
      << "  \"extinction_per_metre\": " << num(s.extinction) << ",\n"
      << "  \"albedo\": 1,\n"
      << "  \"phase\": {\"type\": \"dual_hg\", \"g_forward\": " << num(s.hg_forward) << ", \"g_back\": " << num(s.hg_back)
      << ", \"forward_weight\": " << num(s.hg_forward_weight) << "},\n"
      << "  \"width\": " << s.width << ",\n"
      << "  \"height\": " << s.height << ",\n"
      << "  \"camera\": {\"position\": " << vec3(s.camera.position) << ", \"look_at\": " << vec3(s.camera.look_at) << ", \"up\": " << vec3(s.camera.up)
      << ", \"fov_y_deg\": " << num(s.camera.fov_deg) << "},\n"
      << "  \"sun\": {\"direction_to_sun\": " << vec3(sun) << ", \"atlas_colour\": " << vec3(s.sun_colour) << ", \"irradiance_rgb\": "
      << vec3(Vec3d{{four_pi * s.sun_colour[0], four_pi * s.sun_colour[1], four_pi * s.sun_colour[2]}}) << ", \"angle_deg\": 0},\n"
      << "  \"sky\": {\"zenith_rgb\": " << vec3(s.sky_colour) << ", \"horizon_rgb\": " << vec3(horizon)
      << ", \"model\": \"lerp(horizon, zenith, saturate(dir.z)); below the horizon: horizon\"},\n"
      << "  \"atlas\": {\"artistic\": " << (s.artistic ? "true" : "false") << ", \"ms_octaves\": " << s.ms_octaves << ", \"quality\": " << num(s.quality)
      << ", \"mode\": \"" << (s.mode == render::RenderMode::Fast ? "fast" : "reference") << "\"}\n"
      << "}\n";
    const std::filesystem::path json = dir / "scene.json";
    std::ofstream f(json);
    f << j.str();
    if (!f) throw Error(json.string() + ": cannot write the scene description");
    return "exported " + std::to_string(fine[0]) + "x" + std::to_string(fine[1]) + "x" + std::to_string(fine[2]) + " density and scene.json to " +
           dir.string() + " (" + note + "render it with: blender -b --python scripts/cycles_reference.py -- " + dir.string() + " OUT.exr)";
}

} // namespace atlas::cli

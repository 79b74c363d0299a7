#include "export_scene.h"

#include "atlas/core/files.h"

#include "atlas/core/error.h"
#include "atlas/io/vdb.h"
#include "atlas/render/layer.h"

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

namespace {

// Blender 3.4's Cycles draws a VDB's active tiles as empty (a uniform 8^3
// block that OpenVDB prunes into a tile vanishes): raise every other non-zero
// voxel by one float ulp (1e-7 relative) so no block is uniform.
void break_uniform_blocks(Field3D& density) {
    const Vec3i r = density.resolution();
    for (int z = 0; z < r[2]; ++z)
        for (int y = 0; y < r[1]; ++y)
            for (int x = 0; x < r[0]; ++x) {
                float& v = density.at(0, x, y, z);
                if (v > 0 && ((x + y + z) & 1)) v = std::nextafter(v, std::numeric_limits<float>::infinity());
            }
}

// DIR/density.vdb and DIR/scene.json; `extra` is added to the JSON object
// (lines ending in ",\n").
void write_scene(const std::filesystem::path& dir, Field3D& density, const render::RenderSettings& s, const std::string& extra) {
    break_uniform_blocks(density);
    io::write_vdb(density, dir / "density.vdb");
    const Vec3i fine = density.resolution();
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
      << extra
      << "  \"atlas\": {\"artistic\": " << (s.artistic ? "true" : "false") << ", \"ms_octaves\": " << s.ms_octaves << ", \"quality\": " << num(s.quality)
      << ", \"mode\": \"" << (s.mode == render::RenderMode::Fast ? "fast" : "reference") << "\"}\n"
      << "}\n";
    const std::filesystem::path json = dir / "scene.json";
    const std::string text = j.str();
    write_file_atomic(json, [&](const std::filesystem::path& tmp) { write_file_checked(tmp, text.data(), text.size()); });
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
    write_scene(dir, density, s, "");
    return "exported " + std::to_string(fine[0]) + "x" + std::to_string(fine[1]) + "x" + std::to_string(fine[2]) + " density and scene.json to " +
           dir.string() + " (" + note + "render it with: blender -b --python scripts/cycles_reference.py -- " + dir.string() + " OUT.exr)";
}

std::string export_layer_scene(const std::filesystem::path& dir, render::LayerScene& layer, const render::RenderSettings& s, double patch) {
    if (!s.lights.empty() || !s.light_fields.empty()) throw Error("--export-scene: point lights and lightning are not exported (only sun and sky)");
    if (!(patch > 0) || !std::isfinite(patch)) throw Error("--export-scene: the layer patch size must be > 0 metres");
    std::filesystem::create_directories(dir);
    // The patch: a square of `patch` metres centred under the camera's look-at
    // point. Coverage outside it is set to 0 and the map does not continue
    // beyond its bounds, so the preview that follows draws only the patch.
    const Vec2d c{{s.camera.look_at[0], s.camera.look_at[1]}};
    const double h = 0.5 * patch;
    auto ndf = std::make_shared<Field2D>(*layer.ndf);
    const int cc = ndf->find_channel("coverage");
    for (int y = 0; y < ndf->height(); ++y)
        for (int x = 0; x < ndf->width(); ++x) {
            const Vec2d t = ndf->texel_center(x, y);
            if (std::fabs(t[0] - c[0]) > h || std::fabs(t[1] - c[1]) > h) ndf->at(cc, x, y) = 0;
        }
    layer.ndf = ndf;
    layer.edge = render::MapEdge::Empty;
    // What Cycles has no counterpart for: aerial haze, the rain's thicker
    // light path, 2D sky layers; the envelope maps describe the unmasked set.
    layer.haze_distance = 0;
    layer.rain_absorption = 0;
    layer.sky_layers.clear();
    layer.envelope = {};
    render::validate_layer_scene(layer);
    // The bake box: the patch plus the clouds' reach beyond it (layer_reach:
    // the bilinear footprint of a texel, the curl distortion and the tops'
    // downwind skew); from the shell's bottom
    // lowered by the Earth's curvature at the box's corners (the density is
    // the curved-Earth layer's: layer_density at world points) to its top.
    const double margin = render::layer_reach(layer);
    const Box2d mb = ndf->bounds();
    const Vec2d mc{{0.5 * (mb.min[0] + mb.max[0]), 0.5 * (mb.min[1] + mb.max[1])}};
    const double far = std::hypot(std::fabs(c[0] - mc[0]) + h + margin, std::fabs(c[1] - mc[1]) + h + margin);
    const double drop = far * far / (2 * layer.earth_radius);
    const render::LayerShell shell = render::layer_shell(layer);
    Box3d box{{{c[0] - h - margin, c[1] - h - margin, shell.bottom - drop - 10}}, {{c[0] + h + margin, c[1] + h + margin, shell.top + 10}}};
    const double side = box.max[0] - box.min[0];
    const int nxy = 384;
    const double voxel = side / nxy;
    const int nz = std::clamp(static_cast<int>(std::ceil((box.max[2] - box.min[2]) / voxel)), 1, 512);
    box.max[2] = box.min[2] + nz * voxel;
    Field3D density({{nxy, nxy, nz}}, 1, box, {"density"});
    std::vector<Vec3d> pts(size_t(nxy) * nxy);
    double edge_max = 0;
    for (int z = 0; z < nz; ++z) {
        for (int y = 0; y < nxy; ++y)
            for (int x = 0; x < nxy; ++x)
                pts[size_t(y) * nxy + x] = {{box.min[0] + (x + 0.5) * voxel, box.min[1] + (y + 0.5) * voxel, box.min[2] + (z + 0.5) * voxel}};
        const std::vector<double> d = render::layer_density(layer, pts);
        for (int y = 0; y < nxy; ++y)
            for (int x = 0; x < nxy; ++x) {
                const double v = d[size_t(y) * nxy + x];
                density.at(0, x, y, z) = static_cast<float>(v);
                if (x == 0 || y == 0 || x == nxy - 1 || y == nxy - 1 || z == 0 || z == nz - 1) edge_max = std::max(edge_max, v);
            }
    }
    std::ostringstream extra;
    extra << "  \"layer\": {\"patch_centre\": [" << num(c[0]) << ", " << num(c[1]) << "], \"patch_metres\": " << num(patch)
          << ", \"earth_radius\": " << num(layer.earth_radius) << ", \"curvature_drop_metres\": " << num(drop)
          << ", \"boundary_max_density\": " << num(edge_max)
          << ", \"background\": \"Atlas draws ground below the horizon; compare with Cycles' transparent film over Atlas's own background\"},\n";
    write_scene(dir, density, s, extra.str());
    return "exported the 2.5D layer's density over a " + num(patch) + " m patch centred at (" + num(c[0]) + ", " + num(c[1]) + ") as " +
           std::to_string(nxy) + "x" + std::to_string(nxy) + "x" + std::to_string(nz) + " voxels of " + num(voxel) + " m (curved Earth: " +
           num(drop) + " m drop at the corners; largest density on the box faces " + num(edge_max) + ") and scene.json to " + dir.string() +
           " (the preview draws only the patch, without haze, rain absorption or sky layers)";
}

} // namespace atlas::cli

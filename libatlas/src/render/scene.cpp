#include "atlas/render/scene.h"

#include "atlas/core/error.h"

#include <cmath>
#include <numbers>

namespace atlas::render {

namespace {

void require_channels(const Field3D& set, const std::vector<std::string>& names) {
    for (const auto& n : names)
        if (set.find_channel(n) < 0)
            throw Error("render: NVDF set has no channel '" + n + "' (expected dimensional_profile, detail_type, density_scale, sdf)");
}

} // namespace

CloudScene scene_from_nvdf_set(Field3DPtr vdb_set, Field3DPtr noise, double noise_tile) {
    if (!vdb_set) throw Error("render: NVDF set is missing");
    CloudScene s;
    require_channels(*vdb_set, {"dimensional_profile", "detail_type", "density_scale", "sdf"});
    // No copies: the sampler finds all four channels by name, so modeling
    // and sdf share the set (a 512x512x64 set is 268 MB; copying its
    // channels doubled the preview's peak memory).
    s.modeling = vdb_set;
    s.sdf = vdb_set;
    s.noise = std::move(noise);
    s.noise_tile = noise_tile;
    validate_scene(s);
    return s;
}

void validate_scene(const CloudScene& s) {
    if (!s.modeling) throw Error("render: scene.modeling is missing (expected the modeling NVDF)");
    if (!s.sdf) throw Error("render: scene.sdf is missing (expected the SDF in metres)");
    // Each channel the sampler reads from the field: by name, else its index.
    const Field3D& m = *s.modeling;
    auto present = [&](const char* name, int index) { return m.find_channel(name) >= 0 || index < m.channels(); };
    const bool type_ok = s.uniform_detail_type || present("detail_type", 1);
    const bool scale_ok = s.uniform_density_scale || present("density_scale", 2);
    if (!present("dimensional_profile", 0) || !type_ok || !scale_ok)
        throw Error("render: scene.modeling has " + std::to_string(m.channels()) +
                    " channels, expected 3 (dimensional_profile, detail_type, density_scale)");
    if (s.uniform_detail_type && !std::isfinite(*s.uniform_detail_type)) throw Error("render: uniform_detail_type must be finite");
    if (s.uniform_density_scale && !std::isfinite(*s.uniform_density_scale)) throw Error("render: uniform_density_scale must be finite");
    if (!(s.sdf_block >= 1 && s.sdf_block <= 64 && (s.sdf_block & (s.sdf_block - 1)) == 0))
        throw Error("render: sdf_block must be a power of two from 1 to 64, got " + std::to_string(s.sdf_block));
    Vec3i want = s.modeling->resolution();
    for (int a = 0; a < 3; ++a) want[a] = (want[a] + s.sdf_block - 1) / s.sdf_block;
    if (s.sdf->resolution() != want || !(s.sdf->bounds() == s.modeling->bounds()))
        throw Error(s.sdf_block == 1 ? "render: scene.sdf must have the modeling NVDF's resolution and bounds"
                                     : "render: scene.sdf must have the modeling NVDF's bounds and its resolution / sdf_block (rounded up)");
    if (s.noise && !(std::isfinite(s.noise_tile) && s.noise_tile > 0))
        throw Error("render: noise_tile must be a finite number of metres > 0, got " + std::to_string(s.noise_tile));
}

Vec3d sun_direction(double azimuth_deg, double elevation_deg) {
    const double a = azimuth_deg * std::numbers::pi / 180, e = elevation_deg * std::numbers::pi / 180;
    return {{std::cos(e) * std::sin(a), -std::cos(e) * std::cos(a), std::sin(e)}};
}

Camera framing_camera(const Box3d& b, double aspect, double azimuth_deg, double elevation_deg, double fov_deg) {
    if (!b.valid()) throw Error("render: cannot frame invalid volume bounds");
    if (!(aspect > 0) || !std::isfinite(aspect)) throw Error("render: framing aspect must be > 0");
    const Vec3d centre = (b.min + b.max) * 0.5;
    const double radius = 0.5 * length(b.size());
    const double half = 0.5 * fov_deg * std::numbers::pi / 180;
    const double half_min = std::min(half, std::atan(std::tan(half) * aspect));
    const double dist = radius / std::sin(half_min);
    Camera c;
    c.fov_deg = fov_deg;
    c.look_at = centre;
    c.position = centre + sun_direction(azimuth_deg, elevation_deg) * dist;
    return c;
}

} // namespace atlas::render

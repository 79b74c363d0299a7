// Small synthetic scenes for the render tests (built here, independently of
// the volume module).
#pragma once

#include "atlas/noise/value_noise.h"
#include "atlas/render/scene.h"

#include <cmath>
#include <cstring>
#include <functional>
#include <memory>

namespace atlas::render::testing {

// Two images with the same shape and the same bytes in every channel.
inline bool same_bytes(const Field2D& a, const Field2D& b) {
    if (a.channels() != b.channels() || a.width() != b.width() || a.height() != b.height()) return false;
    for (int c = 0; c < a.channels(); ++c)
        if (std::memcmp(a.channel(c).data(), b.channel(c).data(), a.channel(c).size_bytes()) != 0) return false;
    return true;
}

// A res^3 grid over [0, size]^3 with the modeling channels and SDF from
// callbacks of the world position.
inline CloudScene make_scene(int res, double size, const std::function<double(Vec3d)>& sdf,
                             const std::function<double(Vec3d, double sdf)>& profile, double type = 0, double scale = 1) {
    Box3d b{{{0, 0, 0}}, {{size, size, size}}};
    auto m = std::make_shared<Field3D>(Vec3i{{res, res, res}}, 3, b, std::vector<std::string>{"dimensional_profile", "detail_type", "density_scale"});
    auto s = std::make_shared<Field3D>(Vec3i{{res, res, res}}, 1, b, std::vector<std::string>{"sdf"});
    for (int z = 0; z < res; ++z)
        for (int y = 0; y < res; ++y)
            for (int x = 0; x < res; ++x) {
                Vec3d p = m->voxel_center(x, y, z);
                double d = sdf(p);
                s->at(0, x, y, z) = static_cast<float>(d);
                m->at(0, x, y, z) = static_cast<float>(profile(p, d));
                m->at(1, x, y, z) = static_cast<float>(type);
                m->at(2, x, y, z) = static_cast<float>(scale);
            }
    CloudScene sc;
    sc.modeling = m;
    sc.sdf = s;
    return sc;
}

// A sphere of `radius` at the centre; profile ramps to 1 at depth/2 inside.
inline CloudScene sphere_scene(int res, double size, double radius, double type = 0, double scale = 1) {
    const Vec3d c{{size / 2, size / 2, size / 2}};
    return make_scene(
        res, size, [&](Vec3d p) { return length(p - c) - radius; },
        [&](Vec3d, double d) { return std::clamp(-d / (radius * 0.5), 0.0, 1.0); }, type, scale);
}

// A 4-channel value-noise volume (two frequencies per pair), tiling.
inline Field3DPtr make_noise(int res) {
    auto n = std::make_shared<Field3D>(Vec3i{{res, res, res}}, 4, Box3d{{{0, 0, 0}}, {{1, 1, 1}}});
    const int periods[4] = {4, 8, 4, 8};
    for (int c = 0; c < 4; ++c)
        for (int z = 0; z < res; ++z)
            for (int y = 0; y < res; ++y)
                for (int x = 0; x < res; ++x) {
                    const double f = double(periods[c]) / res;
                    n->at(c, x, y, z) = noise::value_noise((x + 0.5) * f, (y + 0.5) * f, (z + 0.5) * f,
                                                            Vec3i{{periods[c], periods[c], periods[c]}}, uint32_t(7 + c));
                }
    return n;
}

} // namespace atlas::render::testing

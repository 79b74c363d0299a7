// Unity HDRP cloud layer: the XY map projected onto a lat-long sky dome.
#include "atlas/ndf/exporters.h"
#include "atlas/ndf/ndf_set.h"

#include "atlas/core/error.h"

#include "atlas/core/parallel.h"

#include <cmath>
#include <numbers>

namespace atlas::ndf {

namespace {
void check_channel(const Field2D* f, int c, const char* name) {
    if (f && (c < 0 || c >= f->channels()))
        throw Error(std::string("unity cloud layer: '") + name + "_channel' " + std::to_string(c) + " is not a channel of the '" + name +
                    "' map (it has " + std::to_string(f->channels()) + ")");
}
} // namespace

Field2D unity_cloud_layer(const Field2D& set, const Field2D* cirrus, int cirrus_channel, const Field2D* wispy, int wispy_channel,
                          const UnityCloudLayerOptions& o, const MemoryBudget* budget) {
    check_ndf_set(set);
    if (!(o.altitude > 0) || !std::isfinite(o.altitude)) throw Error("unity cloud layer: 'altitude' must be > 0 and finite (m above the eye)");
    if (!std::isfinite(o.eye[0]) || !std::isfinite(o.eye[1])) throw Error("unity cloud layer: 'eye' must be finite");
    check_channel(cirrus, cirrus_channel, "cirrus");
    check_channel(wispy, wispy_channel, "wispy");
    const int W = o.resolution[0], H = o.resolution[1];
    const Box2d deg{{{0, o.upper_hemisphere_only ? 0.0 : -90.0}}, {{360, 90}}};
    Field2D out({{W, H}}, 4, deg, {"r", "g", "b", "a"}, budget);
    const double pi = std::numbers::pi;
    // Beyond the map: wrap (a tiling world) or nothing.
    auto sample = [&](const Field2D& f, int c, Vec2d p) -> float {
        const Box2d& b = f.bounds();
        if (!o.tileable && !(p[0] >= b.min[0] && p[0] <= b.max[0] && p[1] >= b.min[1] && p[1] <= b.max[1])) return 0.0f;
        return f.sample_world(c, p, o.tileable ? WrapMode::Wrap : WrapMode::Clamp);
    };
    parallel_for_index(H, [&](int y) {
        const double theta = o.upper_hemisphere_only ? 0.5 * pi * (y + 0.5) / H : -0.5 * pi + pi * (y + 0.5) / H;
        if (!(theta > 0)) return; // below the horizon: the cloud plane is not seen (zero-filled)
        const double d = o.altitude / std::tan(theta);
        for (int x = 0; x < W; ++x) {
            const double phi = 2.0 * pi * (x + 0.5) / W;
            const Vec2d p{{o.eye[0] + d * std::cos(phi), o.eye[1] + d * std::sin(phi)}};
            if (!std::isfinite(p[0]) || !std::isfinite(p[1])) continue;
            const float cov = sample(set, Coverage, p);
            const float w = std::clamp(1.5f * sample(set, Type, p), 0.0f, 1.0f);
            out.at(0, x, y) = cov * w;
            out.at(1, x, y) = cov * (1.0f - w);
            if (cirrus) out.at(2, x, y) = sample(*cirrus, cirrus_channel, p);
            if (wispy) out.at(3, x, y) = sample(*wispy, wispy_channel, p);
        }
    });
    return out;
}

} // namespace atlas::ndf

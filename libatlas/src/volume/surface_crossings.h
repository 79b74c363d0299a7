// Internal: the iso-crossing points shared by the SDF methods.
#pragma once

#include "atlas/core/error.h"
#include "atlas/core/field.h"
#include "atlas/volume/sdf.h"

#include <cmath>
#include <string>

namespace atlas::volume::detail {

inline bool is_inside(float d, float iso) { return d > iso; }

// Parameter t in [0, 1] of the crossing between samples a (at 0) and b (at 1),
// one inside and one outside: linear interpolation of the density.
inline double crossing_t(float a, float b, float iso) {
    const double den = double(b) - double(a);
    double t = den != 0 ? (double(iso) - double(a)) / den : 0.5;
    return t < 0 ? 0 : (t > 1 ? 1 : t);
}

// Validates options and the density (NaN/Inf -> atlas::Error naming the voxel).
inline void check_density(const Field3D& density, const SdfOptions& o, const char* who) {
    if (o.channel < 0 || o.channel >= density.channels())
        throw Error(std::string(who) + ": channel " + std::to_string(o.channel) + " does not exist (the density has " +
                    std::to_string(density.channels()) + ")");
    if (!std::isfinite(o.iso)) throw Error(std::string(who) + ": iso must be finite");
    if (!std::isfinite(o.far_distance)) throw Error(std::string(who) + ": far_distance must be finite");
    auto d = density.channel(o.channel);
    for (size_t i = 0; i < d.size(); ++i) {
        if (!std::isfinite(d[i])) {
            const size_t nx = size_t(density.nx()), ny = size_t(density.ny());
            throw Error(std::string(who) + ": density is not finite (" + std::to_string(d[i]) + ") at voxel (" +
                        std::to_string(i % nx) + ", " + std::to_string((i / nx) % ny) + ", " + std::to_string(i / (nx * ny)) + ")");
        }
    }
}

inline double far_value(const Field3D& f, const SdfOptions& o) {
    if (o.far_distance > 0) return o.far_distance;
    const Vec3d s = f.bounds().size();
    return std::sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
}

} // namespace atlas::volume::detail

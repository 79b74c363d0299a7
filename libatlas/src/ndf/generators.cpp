// Gradients and tileable noise (painted shapes are in shapes.cpp).
#include "atlas/ndf/generators.h"

#include "atlas/core/error.h"
#include "atlas/noise/value_fbm.h"

#include "atlas/core/parallel.h"

#include <cmath>

namespace atlas::ndf {

namespace {
Field2D new_map(Vec2i res, Box2d bounds, const MemoryBudget* budget) {
    if (!bounds.valid()) throw Error("ndf: bounds must be finite with max > min");
    return Field2D(res, 1, bounds, {"value"}, budget);
}
bool finite2(Vec2d p) { return std::isfinite(p[0]) && std::isfinite(p[1]); }

} // namespace

Field2D gradient_linear(Vec2i res, Box2d bounds, Vec2d p0, Vec2d p1, const MemoryBudget* budget) {
    if (!finite2(p0) || !finite2(p1)) throw Error("gradient: 'start' and 'end' must be finite");
    const Vec2d d = p1 - p0;
    const double len2 = dot(d, d);
    if (!(len2 > 0) || !std::isfinite(len2)) throw Error("gradient: 'end' must differ from 'start' (got the same point or an overflowing distance)");
    Field2D f = new_map(res, bounds, budget);
    auto out = f.channel(0);
    parallel_for_index(res[1], [&](int y) {
        for (int x = 0; x < res[0]; ++x) {
            const double t = dot(f.texel_center(x, y) - p0, d) / len2;
            out[f.index(x, y)] = float(std::clamp(t, 0.0, 1.0));
        }
    });
    return f;
}

Field2D gradient_radial(Vec2i res, Box2d bounds, Vec2d center, double radius, const MemoryBudget* budget) {
    if (!finite2(center)) throw Error("gradient: 'center' must be finite");
    if (!(radius > 0) || !std::isfinite(radius)) throw Error("gradient: 'radius' must be > 0 and finite");
    Field2D f = new_map(res, bounds, budget);
    auto out = f.channel(0);
    parallel_for_index(res[1], [&](int y) {
        for (int x = 0; x < res[0]; ++x) {
            const double r = length(f.texel_center(x, y) - center);
            out[f.index(x, y)] = float(std::clamp(1.0 - r / radius, 0.0, 1.0));
        }
    });
    return f;
}

Field2D noise2d(Vec2i res, Box2d bounds, Vec2i period, int octaves, double gain, uint32_t seed, const MemoryBudget* budget) {
    if (period[0] < 1 || period[1] < 1) throw Error("noise: 'period' must be >= 1 lattice cell per axis");
    if (octaves < 1 || octaves > 16) throw Error("noise: 'octaves' must be in [1, 16]");
    if (!(gain >= 0 && gain <= 1)) throw Error("noise: 'gain' must be in [0, 1]");
    Field2D f = new_map(res, bounds, budget);
    auto out = f.channel(0);
    noise::value_fbm_map(out, res, period, noise::ValueFbm{.octaves = octaves, .gain = gain, .seed = seed});
    parallel_for_each(out.size(), 4096, [&](size_t i) { out[i] = std::clamp(out[i], 0.0f, 1.0f); });
    return f;
}

} // namespace atlas::ndf

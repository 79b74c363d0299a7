// Gradients and tileable noise (painted shapes are in shapes.cpp).
#include "atlas/ndf/generators.h"

#include "atlas/core/error.h"
#include "atlas/noise/value_noise.h"

#include <tbb/parallel_for.h>

#include <cmath>

namespace atlas::ndf {

namespace {
Field2D new_map(Vec2i res, Box2d bounds, const MemoryBudget* budget) {
    if (!bounds.valid()) throw Error("ndf: bounds must be finite with max > min");
    return Field2D(res, 1, bounds, {"value"}, budget);
}
bool finite2(Vec2d p) { return std::isfinite(p[0]) && std::isfinite(p[1]); }

// 2D value noise (z fixed at a lattice plane) at texel centres x = (i + 0.5) dx:
// a row's lattice values come from the noise library at integer points
// (where its interpolation returns the lattice value exactly), blended once
// in y, then only the x interpolation runs per texel - the library's row
// function would hash 8 corners per texel for the same result up to float
// rounding. Same quintic fade, same tiling. The x taps and fade weights are
// the same for every row, so they are computed once per octave.
float quintic(float t) { return t * t * t * (t * (t * 6.0f - 15.0f) + 10.0f); }
struct XTaps {
    std::vector<int> i0, i1;
    std::vector<float> t;
};
XTaps x_taps(int n, double dx, int period) {
    XTaps k;
    k.i0.resize(size_t(n));
    k.i1.resize(size_t(n));
    k.t.resize(size_t(n));
    for (int i = 0; i < n; ++i) {
        const double x = (double(i) + 0.5) * dx;
        const double fx = std::floor(x);
        const int64_t xi = int64_t(fx);
        k.t[size_t(i)] = quintic(float(x - fx));
        k.i0[size_t(i)] = int(xi % period);
        k.i1[size_t(i)] = int((xi + 1) % period);
    }
    return k;
}
void value_noise_row_2d(std::vector<float>& out, std::vector<float>& lat, const XTaps& k, double y, Vec3i p, uint32_t seed) {
    const double fy = std::floor(y);
    const float ty = quintic(float(y - fy));
    const int y0 = int(int64_t(fy) % p[1]), y1 = int((int64_t(fy) + 1) % p[1]);
    lat.resize(size_t(p[0]));
    for (int i = 0; i < p[0]; ++i) {
        const float a = noise::value_noise(double(i), double(y0), 0.0, p, seed);
        const float b = noise::value_noise(double(i), double(y1), 0.0, p, seed);
        lat[size_t(i)] = a + (b - a) * ty;
    }
    for (size_t i = 0; i < out.size(); ++i) {
        const float a = lat[size_t(k.i0[i])], b = lat[size_t(k.i1[i])];
        out[i] = a + (b - a) * k.t[i];
    }
}
} // namespace

Field2D gradient_linear(Vec2i res, Box2d bounds, Vec2d p0, Vec2d p1, const MemoryBudget* budget) {
    if (!finite2(p0) || !finite2(p1)) throw Error("gradient: 'start' and 'end' must be finite");
    const Vec2d d = p1 - p0;
    const double len2 = dot(d, d);
    if (!(len2 > 0) || !std::isfinite(len2)) throw Error("gradient: 'end' must differ from 'start' (got the same point or an overflowing distance)");
    Field2D f = new_map(res, bounds, budget);
    auto out = f.channel(0);
    tbb::parallel_for(0, res[1], [&](int y) {
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
    tbb::parallel_for(0, res[1], [&](int y) {
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
    double norm = 0, amp = 1;
    for (int o = 0; o < octaves; ++o, amp *= gain) norm += amp;
    // Octave o: lattice period << o; texel centres in lattice units are
    // (i + 0.5) / res * period, and the lattice repeats every period cells,
    // so the map tiles. Octaves with more than 4 lattice cells per texel use
    // the library's row function instead.
    std::vector<XTaps> taps(static_cast<size_t>(octaves));
    for (int o = 0; o < octaves; ++o) {
        const int px = period[0] << o;
        if (px <= 4 * res[0]) taps[size_t(o)] = x_taps(res[0], double(px) / res[0], px);
    }
    tbb::parallel_for(0, res[1], [&](int y) {
        std::vector<float> row(static_cast<size_t>(res[0]));
        std::vector<float> lattice;
        float* dst = out.data() + f.index(0, y);
        std::fill(dst, dst + res[0], 0.0f);
        double a = 1.0;
        for (int o = 0; o < octaves; ++o, a *= gain) {
            const Vec3i p{{period[0] << o, period[1] << o, 1}};
            const double dx = double(p[0]) / res[0];
            const double yy = (y + 0.5) * p[1] / res[1];
            const uint32_t s = seed + uint32_t(o) * 1013u;
            if (p[0] <= 4 * res[0]) {
                value_noise_row_2d(row, lattice, taps[size_t(o)], yy, p, s);
            } else {
                noise::value_noise_row(row, 0.5 * dx, dx, yy, 0.0, p, s);
            }
            const float w = float(a / norm);
            for (int x = 0; x < res[0]; ++x) dst[x] += w * row[size_t(x)];
        }
        for (int x = 0; x < res[0]; ++x) dst[x] = std::clamp(dst[x], 0.0f, 1.0f);
    });
    return f;
}

} // namespace atlas::ndf

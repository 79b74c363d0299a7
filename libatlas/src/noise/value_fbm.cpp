// FBM sums of value noise (see atlas/noise/value_fbm.h).
#include "atlas/noise/value_fbm.h"

#include "atlas/core/error.h"
#include "atlas/core/field.h"
#include "atlas/core/hash.h"
#include "atlas/core/parallel.h"

#include <cmath>

namespace atlas::noise {

void ValueFbm::validate() const {
    if (octaves < 1 || octaves > 16) throw Error("noise: 'octaves' must be in [1, 16], got " + std::to_string(octaves));
    if (!(gain >= 0 && gain <= 1)) throw Error("noise: 'gain' must be in [0, 1]");
}

std::vector<float> fbm_weights(const ValueFbm& f) {
    double norm = 0, amp = 1;
    for (int o = 0; o < f.octaves; ++o, amp *= f.gain) norm += amp;
    std::vector<float> w(size_t(std::max(f.octaves, 0)));
    double a = 1.0;
    for (int o = 0; o < f.octaves; ++o, a *= f.gain) w[size_t(o)] = float(a / norm);
    return w;
}

void fill_value_fbm(Field3D& out, int channel, Vec3i period, const ValueFbm& f) {
    f.validate();
    if (channel < 0 || channel >= out.channels()) throw Error("noise: channel " + std::to_string(channel) + " does not exist");
    const Vec3i res = out.resolution();
    const std::vector<float> weights = fbm_weights(f);
    auto dst_channel = out.channel(channel);
    parallel_for_index(res[2], [&](int z) {
        std::vector<float> scratch;
        for (int y = 0; y < res[1]; ++y) {
            std::span<float> dst(dst_channel.data() + out.index(0, y, z), size_t(res[0]));
            value_fbm_row(dst, f, weights, [&](int o) {
                const int scale = 1 << o;
                FbmRow r;
                r.period = {{period[0] * scale, period[1] * scale, period[2] * scale}};
                // Voxel centres in lattice units: (i + 0.5) / res * period.
                r.dx = double(r.period[0]) / res[0];
                r.x0 = 0.5 * r.dx;
                r.y = (y + 0.5) * r.period[1] / res[1];
                r.z = (z + 0.5) * r.period[2] / res[2];
                return r;
            }, scratch);
        }
    });
}

namespace {
// 2D value noise (z fixed at a lattice plane) at texel centres x = (i + 0.5) dx:
// a row's lattice values come from value_noise() at integer points (where its
// interpolation returns the lattice value exactly), blended once in y, then only
// the x interpolation runs per texel - value_noise_row would hash 8 corners per
// texel for the same result up to float rounding. Same quintic fade, same tiling.
// The x taps and fade weights are the same for every row: computed once per octave.
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
        const float a = value_noise(double(i), double(y0), 0.0, p, seed);
        const float b = value_noise(double(i), double(y1), 0.0, p, seed);
        lat[size_t(i)] = a + (b - a) * ty;
    }
    for (size_t i = 0; i < out.size(); ++i) {
        const float a = lat[size_t(k.i0[i])], b = lat[size_t(k.i1[i])];
        out[i] = a + (b - a) * k.t[i];
    }
}
} // namespace

void value_fbm_map(std::span<float> out, Vec2i res, Vec2i period, const ValueFbm& f) {
    f.validate();
    if (period[0] < 1 || period[1] < 1) throw Error("noise: 'period' must be >= 1 lattice cell per axis");
    if (res[0] < 0 || res[1] < 0 || out.size() != size_t(res[0]) * size_t(res[1]))
        throw Error("noise: value_fbm_map's output does not hold res[0] x res[1] values");
    const std::vector<float> weights = fbm_weights(f);
    // Octave o: lattice period << o; texel centres in lattice units are
    // (i + 0.5) / res * period, and the lattice repeats every period cells,
    // so the map tiles. Octaves with more than 4 lattice cells per texel use
    // value_noise_row instead.
    std::vector<XTaps> taps(static_cast<size_t>(f.octaves));
    for (int o = 0; o < f.octaves; ++o) {
        const int px = period[0] << o;
        if (px <= 4 * res[0]) taps[size_t(o)] = x_taps(res[0], double(px) / res[0], px);
    }
    parallel_for_index(res[1], [&](int y) {
        std::vector<float> row(static_cast<size_t>(res[0]));
        std::vector<float> lattice;
        float* dst = out.data() + size_t(y) * size_t(res[0]);
        std::fill(dst, dst + res[0], 0.0f);
        for (int o = 0; o < f.octaves; ++o) {
            const Vec3i p{{period[0] << o, period[1] << o, 1}};
            const double dx = double(p[0]) / res[0];
            const double yy = (y + 0.5) * p[1] / res[1];
            const uint32_t s = f.seed + uint32_t(o) * f.seed_step;
            if (p[0] <= 4 * res[0]) {
                value_noise_row_2d(row, lattice, taps[size_t(o)], yy, p, s);
            } else {
                value_noise_row(row, 0.5 * dx, dx, yy, 0.0, p, s);
            }
            const float w = weights[size_t(o)];
            for (int x = 0; x < res[0]; ++x) dst[x] += w * row[size_t(x)];
        }
    });
}

double smooth_value_noise(uint32_t seed, double x, double y, double z) {
    const double fx = std::floor(x), fy = std::floor(y), fz = std::floor(z);
    const int ix = int(fx), iy = int(fy), iz = int(fz);
    auto s = [](double t) { return t * t * (3 - 2 * t); };
    const double tx = s(x - fx), ty = s(y - fy), tz = s(z - fz);
    double acc = 0;
    for (int c = 0; c < 8; ++c) {
        const int dx = c & 1, dy = (c >> 1) & 1, dz = (c >> 2) & 1;
        const double w = (dx ? tx : 1 - tx) * (dy ? ty : 1 - ty) * (dz ? tz : 1 - tz);
        acc += w * hash_to_unit(hash_coords(seed, ix + dx, iy + dy, iz + dz));
    }
    return acc;
}

} // namespace atlas::noise

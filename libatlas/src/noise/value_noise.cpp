#include "atlas/noise/value_noise.h"

#include "atlas/core/hash.h"

#include <cmath>

namespace atlas::noise {
namespace {

inline int wrap(int64_t i, int period) {
    int64_t r = i % period;
    return int(r < 0 ? r + period : r);
}

inline float quintic(float t) { return t * t * t * (t * (t * 6.0f - 15.0f) + 10.0f); }

inline float lattice(uint32_t seed, int x, int y, int z) { return hash_to_unit(hash_coords(seed, x, y, z)); }

} // namespace

float value_noise(double x, double y, double z, Vec3i period, uint32_t seed) {
    float v;
    value_noise_row(std::span<float>(&v, 1), x, 0.0, y, z, period, seed);
    return v;
}

void value_noise_row(std::span<float> out, double x0, double dx, double y, double z, Vec3i period, uint32_t seed, int64_t first) {
    const int px = period[0] < 1 ? 1 : period[0];
    const int py = period[1] < 1 ? 1 : period[1];
    const int pz = period[2] < 1 ? 1 : period[2];
    // y and z are fixed along the row: resolve their lattice once.
    const double fy = std::floor(y), fz = std::floor(z);
    const float ty = quintic(float(y - fy)), tz = quintic(float(z - fz));
    const int y0 = wrap(int64_t(fy), py), y1 = wrap(int64_t(fy) + 1, py);
    const int z0 = wrap(int64_t(fz), pz), z1 = wrap(int64_t(fz) + 1, pz);
    for (size_t i = 0; i < out.size(); ++i) {
        const double x = x0 + dx * double(first + int64_t(i));
        const double fx = std::floor(x);
        const float tx = quintic(float(x - fx));
        const int xa = wrap(int64_t(fx), px), xb = wrap(int64_t(fx) + 1, px);
        const float c00 = lerp(lattice(seed, xa, y0, z0), lattice(seed, xb, y0, z0), tx);
        const float c10 = lerp(lattice(seed, xa, y1, z0), lattice(seed, xb, y1, z0), tx);
        const float c01 = lerp(lattice(seed, xa, y0, z1), lattice(seed, xb, y0, z1), tx);
        const float c11 = lerp(lattice(seed, xa, y1, z1), lattice(seed, xb, y1, z1), tx);
        out[i] = lerp(lerp(c00, c10, ty), lerp(c01, c11, ty), tz);
    }
}

} // namespace atlas::noise

// Internal: cellular kernels over the 3^D neighbourhood of a sample's cell,
// one feature point per lattice cell:
//   Worley F1/F2 under three metrics, and
//   Alligator (sparse-convolution billows, designed in docs/noise.md).
#pragma once

#include "atlas/noise/noise_spec.h"
#include "lattice.h"

#include <algorithm>
#include <cmath>

namespace atlas::noise::detail {

// Feature point of a cell relative to the cell's corner, in [0, 1)^D,
// pulled towards the centre by 1 - jitter.
inline float feature_offset(uint64_t bits, int axis, float jitter) { return 0.5f + jitter * (bits_unit16(bits, axis) - 0.5f); }

template <WorleyMetric M>
inline float metric_combine(float acc, float d) {
    if constexpr (M == WorleyMetric::Euclidean) return acc + d * d;
    else if constexpr (M == WorleyMetric::Manhattan) return acc + std::fabs(d);
    else return std::max(acc, std::fabs(d));
}

struct F12 {
    float f1, f2;
};

// Nearest and second-nearest feature distances (in cells, metric M); the 3D
// variant is worley3_cached below.
template <WorleyMetric M>
inline F12 worley2(const Lattice<2>& L, const Split& sx, const Split& sy, float jitter) {
    float f1 = 1e30f, f2 = 1e30f;
    const int xs[3] = {sx.prev, sx.cell, sx.next}, ys[3] = {sy.prev, sy.cell, sy.next};
    for (int j = 0; j < 3; ++j)
        for (int i = 0; i < 3; ++i) {
            const uint64_t b = L.bits(xs[i], ys[j]);
            const float dx = float(i - 1) + feature_offset(b, 0, jitter) - sx.frac;
            const float dy = float(j - 1) + feature_offset(b, 1, jitter) - sy.frac;
            const float d = metric_combine<M>(metric_combine<M>(0.0f, dx), dy);
            f2 = std::min(f2, std::max(f1, d));
            f1 = std::min(f1, d);
        }
    if constexpr (M == WorleyMetric::Euclidean) return {std::sqrt(f1), std::sqrt(f2)};
    else return {f1, f2};
}

inline float worley_feature(F12 f, WorleyFeature feature) {
    float v = 0;
    switch (feature) {
    case WorleyFeature::F1: v = f.f1; break;
    case WorleyFeature::F2: v = f.f2; break;
    case WorleyFeature::F2MinusF1: v = f.f2 - f.f1; break;
    case WorleyFeature::InvertedF1: v = 1.0f - f.f1; break;
    }
    return std::clamp(v, 0.0f, 1.0f);
}

// Alligator bump of one feature point: m * (1 - r^2)^3 for r < 1, where r is
// the distance over the radius: C2-smooth and exactly zero from r = 1 on,
// so a 3^D neighbourhood sees every bump when radius <= 1 cell.
inline float alligator_bump(float m, float r2) {
    const float t = std::max(0.0f, 1.0f - r2);
    return m * t * t * t;
}

// Largest minus second-largest bump: creases where two bumps are equal,
// rounded billows of random height in between. Range [0, 1).
// (2D here; the 3D variant is alligator3_cached below.)
inline float alligator2(const Lattice<2>& L, const Split& sx, const Split& sy, float inv_r2) {
    float m1 = 0, m2 = 0;
    const int xs[3] = {sx.prev, sx.cell, sx.next}, ys[3] = {sy.prev, sy.cell, sy.next};
    for (int j = 0; j < 3; ++j)
        for (int i = 0; i < 3; ++i) {
            const uint64_t b = L.bits(xs[i], ys[j]);
            const float dx = float(i - 1) + bits_unit16(b, 0) - sx.frac;
            const float dy = float(j - 1) + bits_unit16(b, 1) - sy.frac;
            const float v = alligator_bump(bits_unit16(b, 3), (dx * dx + dy * dy) * inv_r2);
            m2 = std::max(m2, std::min(m1, v));
            m1 = std::max(m1, v);
        }
    return m1 - m2;
}

// Row coherence: consecutive samples of a row mostly share a cell, so the
// 27 neighbours' feature points (relative to the cell corner) and magnitudes
// are decoded once per cell change. The sample loops below then run over
// flat arrays the compiler can vectorise.
struct CellCache3 {
    int cx = -1, cy = -1, cz = -1;
    float px[27], py[27], pz[27], m[27];

    void load(const Lattice<3>& L, const Split& sx, const Split& sy, const Split& sz, float jitter) {
        if (sx.cell == cx && sy.cell == cy && sz.cell == cz) return;
        cx = sx.cell;
        cy = sy.cell;
        cz = sz.cell;
        const int xs[3] = {sx.prev, sx.cell, sx.next}, ys[3] = {sy.prev, sy.cell, sy.next}, zs[3] = {sz.prev, sz.cell, sz.next};
        for (int k = 0; k < 3; ++k)
            for (int j = 0; j < 3; ++j)
                for (int i = 0; i < 3; ++i) {
                    const int n = (k * 3 + j) * 3 + i;
                    const uint64_t b = L.bits(xs[i], ys[j], zs[k]);
                    px[n] = float(i - 1) + feature_offset(b, 0, jitter);
                    py[n] = float(j - 1) + feature_offset(b, 1, jitter);
                    pz[n] = float(k - 1) + feature_offset(b, 2, jitter);
                    m[n] = bits_unit16(b, 3);
                }
    }
};

template <WorleyMetric M>
inline F12 worley3_cached(const CellCache3& c, float fx, float fy, float fz) {
    float f1 = 1e30f, f2 = 1e30f;
    for (int n = 0; n < 27; ++n) {
        const float d = metric_combine<M>(metric_combine<M>(metric_combine<M>(0.0f, c.px[n] - fx), c.py[n] - fy), c.pz[n] - fz);
        f2 = std::min(f2, std::max(f1, d));
        f1 = std::min(f1, d);
    }
    if constexpr (M == WorleyMetric::Euclidean) return {std::sqrt(f1), std::sqrt(f2)};
    else return {f1, f2};
}

// Same as alligator3 over a loaded cache (jitter 1).
inline float alligator3_cached(const CellCache3& c, float fx, float fy, float fz, float inv_r2) {
    float m1 = 0, m2 = 0;
    for (int n = 0; n < 27; ++n) {
        const float dx = c.px[n] - fx, dy = c.py[n] - fy, dz = c.pz[n] - fz;
        const float v = alligator_bump(c.m[n], (dx * dx + dy * dy + dz * dz) * inv_r2);
        m2 = std::max(m2, std::min(m1, v));
        m1 = std::max(m1, v);
    }
    return m1 - m2;
}

} // namespace atlas::noise::detail

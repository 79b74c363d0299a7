// Internal: the SIMD kernels, written once over an ISA traits class I and
// included by one translation unit per ISA (simd_sse2.cpp, simd_avx2.cpp),
// each inside its own namespace ATLAS_NOISE_ISA, so no symbol is shared
// between translation units compiled with different flags.
//
// Same bytes as the scalar kernels (gradient.h, cellular.h) because every
// sample sees the same IEEE operations in the same order:
// * split: floor in double, u - floor(u) (exact), rounded to float once;
// * gradient: the 8 dot products g0*x + g1*y + g2*z left to right, the same
//   7 lerps, std::clamp's comparisons (MINPS/MAXPS with operands ordered so
//   ties return what std::clamp returns);
// * Worley / Alligator: the 27 distances as in the scalar loop; F1/F2 (and
//   the two largest bumps) are order-free functions of the multiset of
//   distances (no NaN, no -0), so the lanes may hold any subset;
// * no fused multiply-add: the files are compiled with -ffp-contract=off and
//   use only separate multiply and add intrinsics.
#pragma once

#include "simd.h"

#include <cstddef>
#include <cstdint>
#include <cstring>

#ifndef ATLAS_NOISE_ISA
#error "define ATLAS_NOISE_ISA before including simd_kernels.h"
#endif

namespace atlas::noise::detail::ATLAS_NOISE_ISA {

// kGrad3 of gradient.h, component-major, padded to 4 per row (SSE2 loads rows).
alignas(16) inline constexpr float kGradRows[16][4] = {
    {1, 1, 0, 0},  {-1, 1, 0, 0}, {1, -1, 0, 0}, {-1, -1, 0, 0}, {1, 0, 1, 0},  {-1, 0, 1, 0},  {1, 0, -1, 0}, {-1, 0, -1, 0},
    {0, 1, 1, 0},  {0, -1, 1, 0}, {0, 1, -1, 0}, {0, -1, -1, 0}, {1, 1, 0, 0},  {-1, 1, 0, 0},  {0, -1, 1, 0}, {0, -1, -1, 0}};

inline float unit16(uint64_t b, int field) { return float((b >> (16 * field)) & 0xFFFFu) * (1.0f / 65536.0f); }

inline uint64_t bits_at(const LatticeView& L, int x, int y, int z) {
    if (L.table) return L.table[size_t(x) + size_t(L.px) * (size_t(y) + size_t(L.py) * size_t(z))];
    return L.bits(L.lattice, x, y, z);
}

template <class I>
struct Kernels {
    using F = typename I::F;
    using V = typename I::V;
    static constexpr int W = I::W;
    static constexpr int kSlots = (27 + W - 1) / W * W; // neighbours padded to whole vectors

    // Wrapped cell, next and previous cell and fraction of W coordinates (Split of lattice.h).
    static void split_axis(const double* u, double scale, int period, V& c, V& nx, V& pv, F& f) {
        I::split(u, scale, c, f);
        const V P = I::iset(period), one = I::iset(1), zero = I::iset(0);
        c = I::isub(c, I::iand(I::icmpgt(c, I::iset(period - 1)), P)); // c >= period: c -= period
        c = I::iandnot(I::icmpgt(zero, c), c);                           // c < 0: 0
        nx = I::iadd(c, one);
        nx = I::iandnot(I::icmpeq(nx, P), nx);
        pv = I::iadd(I::isub(c, one), I::iand(I::icmpeq(c, zero), P));
    }

    // clamp(v, lo, hi) with std::clamp's result for every input.
    static F clamp(F v, F lo, F hi) { return I::fmax(lo, I::fmin(hi, v)); }
    static float clamp1(float v, float lo, float hi) { return (v < lo) ? lo : (hi < v) ? hi : v; }

    // The batch's coordinates: the caller's arrays, or a padded copy for the tail.
    struct Batch {
        alignas(64) double pad[3][W];
        const double* p[3];
        size_t m;
        Batch(const double* const* u, size_t i0, size_t n) {
            m = n - i0 < size_t(W) ? n - i0 : size_t(W);
            for (int a = 0; a < 3; ++a) {
                if (m == size_t(W)) {
                    p[a] = u[a] + i0;
                    continue;
                }
                for (int l = 0; l < W; ++l) pad[a][l] = u[a][i0 + (size_t(l) < m ? size_t(l) : 0)];
                p[a] = pad[a];
            }
        }
    };

    // A hashed (untabulated) lattice: each lane's 8 corner gradient indices
    // (k = i + 2j + 4kk: x corner i, y corner j, z corner kk), hashing only
    // corners the previous lane's cell did not have. Lanes are consecutive
    // samples along x, so a lane mostly shares its cell, or its cell's x - 1
    // face, with the one before. Hashing all 8 per lane through bits() ran
    // AVX2 at 10.6 M samples/s at period 256, no faster than the scalar path
    // (58 with the table); docs/PERFORMANCE.md.
    struct HashedCorners {
        bool valid = false;
        int x0 = 0, x1 = 0, y0 = 0, z0 = 0;
        int h[8] = {};

        void fill(const LatticeView& L, const V (&c)[3][2], int (&hs)[8][W]) {
            alignas(64) int xs[2][W], ys[2][W], zs[2][W];
            for (int e = 0; e < 2; ++e) {
                I::istore(xs[e], c[0][e]);
                I::istore(ys[e], c[1][e]);
                I::istore(zs[e], c[2][e]);
            }
            for (int l = 0; l < W; ++l) {
                const int nx0 = xs[0][l], nx1 = xs[1][l], ny0 = ys[0][l], nz0 = zs[0][l];
                // y1 and z1 follow from y0 and z0 (the same wrap), x1 from x0.
                const bool same_yz = valid && ny0 == y0 && nz0 == z0;
                if (!(same_yz && nx0 == x0)) {
                    const bool shifted = same_yz && nx0 == x1; // the next cell along x: its x0 face is our x1 face
                    if (shifted)
                        for (int k = 0; k < 8; k += 2) h[k] = h[k + 1];
                    const int cx[2] = {nx0, nx1}, cy[2] = {ny0, ys[1][l]}, cz[2] = {nz0, zs[1][l]};
                    L.corners(L.lattice, cx, cy, cz, shifted ? 1 : 0, h);
                    valid = true;
                    x0 = nx0;
                    x1 = nx1;
                    y0 = ny0;
                    z0 = nz0;
                }
                for (int k = 0; k < 8; ++k) hs[k][l] = h[k];
            }
        }
    };

    static void gradient3(const LatticeView& L, const double* const* u, size_t n, double scale, float* out) {
        const F one = I::fset(1.0f), six = I::fset(6.0f), fifteen = I::fset(15.0f), ten = I::fset(10.0f);
        // px * py is used only with a table (small periods); hashed lattices can have periods
        // whose product overflows int, so it is formed with wrapping unsigned arithmetic.
        const V px = I::iset(L.px), pxy = I::iset(int(uint32_t(L.px) * uint32_t(L.py))), fifteen_i = I::iset(15);
        HashedCorners memo; // hashed lattices: the last lane's cell, across batches
        for (size_t i0 = 0; i0 < n; i0 += size_t(W)) {
            const Batch b(u, i0, n);
            V c[3][2], prev;
            F f[3];
            split_axis(b.p[0], scale, L.px, c[0][0], c[0][1], prev, f[0]);
            split_axis(b.p[1], scale, L.py, c[1][0], c[1][1], prev, f[1]);
            split_axis(b.p[2], scale, L.pz, c[2][0], c[2][1], prev, f[2]);
            F fm[3][2]; // frac - 0, frac - 1
            F fd[3];    // faded
            for (int a = 0; a < 3; ++a) {
                fm[a][0] = I::sub(f[a], I::fset(0.0f));
                fm[a][1] = I::sub(f[a], one);
                const F t = f[a];
                // t * t * t * (t * (t * 6 - 15) + 10), left to right as fade() in gradient.h
                fd[a] = I::mul(I::mul(I::mul(t, t), t), I::add(I::mul(t, I::sub(I::mul(t, six), fifteen)), ten));
            }
            V yo[2], zo[2];
            if (L.table) {
                yo[0] = I::imul(c[1][0], px);
                yo[1] = I::imul(c[1][1], px);
                zo[0] = I::imul(c[2][0], pxy);
                zo[1] = I::imul(c[2][1], pxy);
            }
            alignas(64) int hs[8][W];
            if (!L.table) memo.fill(L, c, hs);
            F nc[8];
            for (int k = 0; k < 8; ++k) {
                const int i = k & 1, j = (k >> 1) & 1, kk = k >> 2;
                V h;
                if (L.table) {
                    const V idx = I::iadd(c[0][i], I::iadd(yo[j], zo[kk]));
                    h = I::iand(I::gather_lo32(L.table, idx), fifteen_i);
                } else {
                    h = I::iload(hs[k]);
                }
                F g0, g1, g2;
                I::grad3(h, g0, g1, g2);
                nc[k] = I::add(I::add(I::mul(g0, fm[0][i]), I::mul(g1, fm[1][j])), I::mul(g2, fm[2][kk]));
            }
            const F uu = fd[0], vv = fd[1], ww = fd[2];
            const F x00 = I::add(nc[0], I::mul(uu, I::sub(nc[1], nc[0]))), x10 = I::add(nc[2], I::mul(uu, I::sub(nc[3], nc[2])));
            const F x01 = I::add(nc[4], I::mul(uu, I::sub(nc[5], nc[4]))), x11 = I::add(nc[6], I::mul(uu, I::sub(nc[7], nc[6])));
            const F y0 = I::add(x00, I::mul(vv, I::sub(x10, x00))), y1 = I::add(x01, I::mul(vv, I::sub(x11, x01)));
            const F v = clamp(I::add(y0, I::mul(ww, I::sub(y1, y0))), I::fset(-1.0f), one);
            if (b.m == size_t(W)) {
                I::fstore(out + i0, v);
            } else {
                alignas(64) float tmp[W];
                I::fstore(tmp, v);
                std::memcpy(out + i0, tmp, b.m * sizeof(float));
            }
        }
    }

    // The 27 neighbours of one cell (CellCache3 of cellular.h), padded with far points.
    struct Cells {
        int cx = -1, cy = -1, cz = -1;
        alignas(64) float px[kSlots], py[kSlots], pz[kSlots], m[kSlots];

        void load(const LatticeView& L, const int (&xs)[3], const int (&ys)[3], const int (&zs)[3], float jitter) {
            if (xs[1] == cx && ys[1] == cy && zs[1] == cz) return;
            cx = xs[1];
            cy = ys[1];
            cz = zs[1];
            for (int k = 0; k < 3; ++k)
                for (int j = 0; j < 3; ++j)
                    for (int i = 0; i < 3; ++i) {
                        const int n = (k * 3 + j) * 3 + i;
                        const uint64_t b = bits_at(L, xs[i], ys[j], zs[k]);
                        px[n] = float(i - 1) + (0.5f + jitter * (unit16(b, 0) - 0.5f));
                        py[n] = float(j - 1) + (0.5f + jitter * (unit16(b, 1) - 0.5f));
                        pz[n] = float(k - 1) + (0.5f + jitter * (unit16(b, 2) - 0.5f));
                        m[n] = unit16(b, 3);
                    }
            for (int n = 27; n < kSlots; ++n) {
                px[n] = py[n] = pz[n] = 1e15f; // farther than any neighbour: never F1/F2, bump 0
                m[n] = 0.0f;
            }
        }
    };

    // Splits a batch and runs per_sample(s, xs, ys, zs, fx, fy, fz) for each of its samples.
    template <class PerSample>
    static void for_each_sample(const LatticeView& L, const double* const* u, size_t n, double scale, PerSample&& per_sample) {
        for (size_t i0 = 0; i0 < n; i0 += size_t(W)) {
            const Batch b(u, i0, n);
            alignas(64) int cs[3][3][W]; // axis, prev/cell/next, lane
            alignas(64) float fs[3][W];
            const int per[3] = {L.px, L.py, L.pz};
            for (int a = 0; a < 3; ++a) {
                V c, nx, pv;
                F f;
                split_axis(b.p[a], scale, per[a], c, nx, pv, f);
                I::istore(cs[a][0], pv);
                I::istore(cs[a][1], c);
                I::istore(cs[a][2], nx);
                I::fstore(fs[a], f);
            }
            for (size_t s = 0; s < b.m; ++s) {
                const int xs[3] = {cs[0][0][s], cs[0][1][s], cs[0][2][s]};
                const int ys[3] = {cs[1][0][s], cs[1][1][s], cs[1][2][s]};
                const int zs[3] = {cs[2][0][s], cs[2][1][s], cs[2][2][s]};
                per_sample(i0 + s, xs, ys, zs, fs[0][s], fs[1][s], fs[2][s]);
            }
        }
    }

    template <WorleyMetric M>
    static void worley3(const LatticeView& L, const double* const* u, size_t n, double scale, float jitter, WorleyFeature feature,
                        float* out) {
        Cells cells;
        for_each_sample(L, u, n, scale, [&](size_t i, const int (&xs)[3], const int (&ys)[3], const int (&zs)[3], float fx, float fy, float fz) {
            cells.load(L, xs, ys, zs, jitter);
            const F vx = I::fset(fx), vy = I::fset(fy), vz = I::fset(fz);
            F f1 = I::fset(1e30f), f2 = f1;
            for (int s = 0; s < kSlots; s += W) {
                const F dx = I::sub(I::fload(cells.px + s), vx), dy = I::sub(I::fload(cells.py + s), vy), dz = I::sub(I::fload(cells.pz + s), vz);
                F d;
                if constexpr (M == WorleyMetric::Euclidean) d = I::add(I::add(I::mul(dx, dx), I::mul(dy, dy)), I::mul(dz, dz));
                else if constexpr (M == WorleyMetric::Manhattan) d = I::add(I::add(I::fabs(dx), I::fabs(dy)), I::fabs(dz));
                else d = I::fmax(I::fmax(I::fabs(dx), I::fabs(dy)), I::fabs(dz));
                f2 = I::fmin(f2, I::fmax(f1, d));
                f1 = I::fmin(f1, d);
            }
            float r1, r2;
            I::reduce_min2(f1, f2, r1, r2);
            if constexpr (M == WorleyMetric::Euclidean) {
                r1 = I::sqrt1(r1);
                r2 = I::sqrt1(r2);
            }
            float v = 0;
            switch (feature) {
            case WorleyFeature::F1: v = r1; break;
            case WorleyFeature::F2: v = r2; break;
            case WorleyFeature::F2MinusF1: v = r2 - r1; break;
            case WorleyFeature::InvertedF1: v = 1.0f - r1; break;
            }
            out[i] = clamp1(v, 0.0f, 1.0f);
        });
    }

    static void alligator3(const LatticeView& L, const double* const* u, size_t n, double scale, float inv_r2, float* out) {
        Cells cells;
        const F vr = I::fset(inv_r2), one = I::fset(1.0f), zero = I::fset(0.0f);
        for_each_sample(L, u, n, scale, [&](size_t i, const int (&xs)[3], const int (&ys)[3], const int (&zs)[3], float fx, float fy, float fz) {
            cells.load(L, xs, ys, zs, 1.0f);
            const F vx = I::fset(fx), vy = I::fset(fy), vz = I::fset(fz);
            F m1 = zero, m2 = zero;
            for (int s = 0; s < kSlots; s += W) {
                const F dx = I::sub(I::fload(cells.px + s), vx), dy = I::sub(I::fload(cells.py + s), vy), dz = I::sub(I::fload(cells.pz + s), vz);
                const F r2 = I::mul(I::add(I::add(I::mul(dx, dx), I::mul(dy, dy)), I::mul(dz, dz)), vr);
                const F t = I::fmax(I::sub(one, r2), zero); // std::max(0, 1 - r2)
                const F v = I::mul(I::mul(I::mul(I::fload(cells.m + s), t), t), t);
                m2 = I::fmax(m2, I::fmin(m1, v));
                m1 = I::fmax(m1, v);
            }
            float r1, r2;
            I::reduce_max2(m1, m2, r1, r2);
            out[i] = r1 - r2;
        });
    }

    static const SimdKernels& table() {
        static const SimdKernels k{&gradient3,
                                   {&worley3<WorleyMetric::Euclidean>, &worley3<WorleyMetric::Manhattan>, &worley3<WorleyMetric::Chebyshev>},
                                   &alligator3};
        return k;
    }
};

} // namespace atlas::noise::detail::ATLAS_NOISE_ISA

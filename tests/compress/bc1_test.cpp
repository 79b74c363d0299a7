// BC1 RGB and bc1-scalar: bounds under every decoder model, one-sided, decoder models.
#include "atlas/compress/bc1.h"
#include "atlas/compress/bc1_scalar.h"

#include "test_blocks.h"
#include "../../libatlas/src/compress/bc1_eval.h" // internal: the AVX2 selection and channel-major palettes

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <thread>
#include <vector>
#include <array>

namespace atlas::compress {
namespace {

using test::kRandomBlocks;
using test::scalar_block;
using test::unit;

// Worst |decoded - source| and decoded - source over the decoders (Conformant: +-tol
// except the 3-colour black).
void check_rgb(const uint8_t blk[8], DecoderSet set, const float src[48], float& max_err, float& max_over, double& ref_sq) {
    max_err = 0; max_over = -1e9f; ref_sq = 0;
    const uint16_t c0 = uint16_t(blk[0] | (blk[1] << 8)), c1 = uint16_t(blk[2] | (blk[3] << 8));
    const uint32_t bits = uint32_t(blk[4]) | (uint32_t(blk[5]) << 8) | (uint32_t(blk[6]) << 16) | (uint32_t(blk[7]) << 24);
    for (Decoder d : decoders_in(set)) {
        float v[48];
        decode_bc1_block(blk, d, v);
        for (int t = 0; t < 16; ++t) {
            const int idx = int((bits >> (2 * t)) & 3);
            float ep[4][3];
            bc1_palette(c0, c1, Decoder::Reference, ep);
            for (int c = 0; c < 3; ++c) {
                const float tol = (d == Decoder::Conformant && !(c0 <= c1 && idx == 3)) ? bc1_conformant_tolerance(ep[0][c], ep[1][c]) : 0.0f;
                max_err = std::max(max_err, std::fabs(v[3 * t + c] - src[3 * t + c]) + tol);
                max_over = std::max(max_over, v[3 * t + c] + tol - src[3 * t + c]);
                if (d == Decoder::Reference) ref_sq += double(v[3 * t + c] - src[3 * t + c]) * double(v[3 * t + c] - src[3 * t + c]);
            }
        }
    }
}

// Each texel's least squared Reference error over the first `entries` entries of a palette
// (bc1_palette) whose error on every channel is within `bound`, summed; +inf when a texel
// has none.
double least_squared_error(const float pal[4][3], int entries, const float src[48], double bound = INFINITY) {
    double sum = 0;
    for (int t = 0; t < 16; ++t) {
        double best = INFINITY;
        for (int i = 0; i < entries; ++i) {
            double e = 0, m = 0;
            for (int c = 0; c < 3; ++c) {
                const double d = double(pal[i][c]) - src[3 * t + c];
                e += d * d;
                m = std::max(m, std::fabs(d));
            }
            if (m <= bound && e < best) best = e;
        }
        sum += best;
    }
    return sum;
}

void rgb_block(uint64_t k, float out[48]) {
    float r[16], g[16], b[16];
    scalar_block(k, 0, 1, r);
    scalar_block(k + 1000003, 0, 1, g);
    scalar_block(k + 2000003, 0, 1, b);
    for (int t = 0; t < 16; ++t) { out[3 * t] = r[t]; out[3 * t + 1] = g[t]; out[3 * t + 2] = b[t]; }
}

// The channel-major palettes the encoder's AVX2 path uses hold the same floats as
// bc1_interval_palette, for random pairs (both modes) under several decoder sets.
TEST(Bc1Eval, ChannelMajorPaletteEqualsIntervalPalette) {
    const DecoderSet sets[] = {kReferenceOnly, kAllDecoders, decoder_bit(Decoder::Nvidia), decoder_bit(Decoder::Conformant),
                               decoder_bit(Decoder::Amd) | decoder_bit(Decoder::Tool8Round), 0};
    for (uint64_t k = 0; k < 20000; ++k) {
        const uint16_t c0 = uint16_t(unit(k, 1) * 65536), c1 = uint16_t(k % 7 == 0 ? c0 : uint16_t(unit(k, 2) * 65536));
        for (DecoderSet set : sets) {
            detail::Palette<3> p;
            detail::Bc1PaletteCm q;
            detail::bc1_interval_palette(c0, c1, set, p);
            detail::bc1_interval_palette_cm(c0, c1, set, q);
            for (int i = 0; i < 4; ++i)
                for (int c = 0; c < 3; ++c) {
                    ASSERT_EQ(std::memcmp(&p.lo[i][c], &q.lo[c][i], 4), 0) << c0 << " " << c1 << " set " << set;
                    ASSERT_EQ(std::memcmp(&p.hi[i][c], &q.hi[c][i], 4), 0) << c0 << " " << c1 << " set " << set;
                    ASSERT_EQ(std::memcmp(&p.ref[i][c], &q.ref[c][i], 4), 0) << c0 << " " << c1 << " set " << set;
                }
        }
    }
}

#if defined(ATLAS_BC1_AVX2)
// The AVX2 selection returns select_indices<3>'s result bit for bit (max error, squared
// error, indices, early exit), two- and one-sided, on random and smooth blocks with random
// pairs and incumbent bounds.
TEST(Bc1Eval, Avx2EqualsSelectIndices) {
    if (!detail::bc1_cpu_has_avx2()) GTEST_SKIP() << "no AVX2 on this CPU";
    for (uint64_t k = 0; k < uint64_t(kRandomBlocks / 5); ++k) {
        float src[48];
        for (int c = 0; c < 3; ++c) {
            float ch[16];
            scalar_block(k * 3 + uint64_t(c), 0.0f, 1.0f, ch);
            for (int t = 0; t < 16; ++t) src[3 * t + c] = ch[t];
        }
        const detail::Bc1Planes planes(src);
        // Equal endpoints (every entry but black ties) and near pairs as well as random ones.
        const uint16_t c0 = uint16_t(unit(k, 1) * 65536);
        const uint16_t c1 = k % 5 == 0 ? c0 : k % 5 == 1 ? uint16_t(c0 ^ (1u << (k % 16))) : uint16_t(unit(k, 2) * 65536);
        const DecoderSet set = k % 3 == 0 ? kAllDecoders : kReferenceOnly;
        detail::Palette<3> p;
        detail::Bc1PaletteCm q;
        detail::bc1_interval_palette(c0, c1, set, p);
        detail::bc1_interval_palette_cm(c0, c1, set, q);
        const float stop = k % 4 == 0 ? float(unit(k, 3)) * 0.2f : INFINITY;
        // No budget, and budgets below and above the palette's least max error; no sum to
        // beat, and one that stops some pairs part way.
        const double sum_stop = k % 3 == 1 ? double(unit(k, 6)) * 0.5 : INFINITY;
        for (float budget : {-1.0f, float(unit(k, 4)) * 0.1f, float(unit(k, 5)) * 0.6f})
            for (bool os : {false, true}) {
                const detail::Selection a = detail::select_indices(p, src, os, stop, budget, sum_stop);
                const detail::Selection b = os ? detail::bc1_select_avx2<true>(q, planes, stop, budget, sum_stop)
                                               : detail::bc1_select_avx2<false>(q, planes, stop, budget, sum_stop);
                if (!std::isfinite(a.max_err)) { // stopped: both, and only a pair over the sum
                    ASSERT_FALSE(std::isfinite(b.max_err)) << "case " << k;
                    const detail::Selection full = detail::select_indices(p, src, os, stop, budget);
                    ASSERT_TRUE(!std::isfinite(full.max_err) || full.sum_sq > sum_stop) << "case " << k;
                    continue;
                }
                ASSERT_EQ(std::memcmp(&a.max_err, &b.max_err, 4), 0) << "case " << k << " os " << os << " budget " << budget;
                ASSERT_EQ(std::memcmp(&a.sum_sq, &b.sum_sq, 8), 0) << "case " << k << " os " << os << " budget " << budget;
                ASSERT_EQ(std::memcmp(a.idx, b.idx, 16), 0) << "case " << k << " os " << os << " budget " << budget;
            }
    }
}
#endif

TEST(Bc1, RandomBlocksReportedErrorBoundsEveryDecoder) {
    BlockOptions o;
    o.quality = Quality::Fast;
    o.decoders = kAllDecoders;
    for (int k = 0; k < kRandomBlocks; ++k) {
        float src[48];
        rgb_block(uint64_t(k), src);
        uint8_t blk[8];
        BlockResult r = encode_bc1_block(src, o, blk);
        float e, over;
        double sq;
        check_rgb(blk, kAllDecoders, src, e, over, sq);
        ASSERT_LE(e, r.max_error + 1e-6f) << k;
        ASSERT_NEAR(sq, r.sum_sq, 1e-6 + 1e-6 * r.sum_sq) << k;
    }
}

TEST(Bc1, NormalImprovesOnFastAndBestOnNormal) {
    BlockOptions f, n, b;
    f.quality = Quality::Fast; n.quality = Quality::Normal; b.quality = Quality::Best;
    double ef = 0, en = 0, eb = 0;
    for (int k = 0; k < 2000; ++k) {
        float src[48];
        rgb_block(uint64_t(k) * 3 + 1, src);
        uint8_t blk[8];
        const float a = encode_bc1_block(src, f, blk).max_error;
        const float c = encode_bc1_block(src, n, blk).max_error;
        const float d = encode_bc1_block(src, b, blk).max_error;
        EXPECT_LE(c, a);
        EXPECT_LE(d, c);
        ef += a; en += c; eb += d;
    }
    EXPECT_LT(en, ef);
    EXPECT_LT(eb, en);  // best finds a better endpoint pair somewhere in 2000 blocks
}

// For a fixed palette and a budget, the selection is the least squared Reference error
// over every assignment of entries whose worst-case error stays within the budget (or
// within the palette's least max error when the budget is below it): checked against
// all 4^16 assignments, pruned texel by texel, decoded by the public decoders.
TEST(Bc1, BudgetedSelectionIsTheLeastSquaredErrorWithinTheBudget) {
    for (uint64_t k = 0; k < 400; ++k) {
        float src[48];
        rgb_block(k * 11 + 5, src);
        const uint16_t c0 = uint16_t(unit(k, 1) * 65536), c1 = uint16_t(unit(k, 2) * 65536);
        const DecoderSet set = k % 2 ? kAllDecoders : kReferenceOnly;
        // Each entry's worst-case error per texel over the decoders, and its Reference error.
        float worst[16][4] = {}, ref[16][4] = {};
        for (Decoder d : decoders_in(set)) {
            float pal[4][3];
            bc1_palette(c0, c1, d, pal);
            float rp[4][3];
            bc1_palette(c0, c1, Decoder::Reference, rp);
            for (int t = 0; t < 16; ++t)
                for (int i = 0; i < 4; ++i) {
                    double sq = 0;
                    for (int c = 0; c < 3; ++c) {
                        const float tol = (d == Decoder::Conformant && !(c0 <= c1 && i == 3)) ? bc1_conformant_tolerance(rp[0][c], rp[1][c]) : 0.0f;
                        worst[t][i] = std::max(worst[t][i], std::fabs(pal[i][c] - src[3 * t + c]) + tol);
                        sq += double(rp[i][c] - src[3 * t + c]) * double(rp[i][c] - src[3 * t + c]);
                    }
                    ref[t][i] = float(sq);
                }
        }
        float least_max = 0;
        for (int t = 0; t < 16; ++t) least_max = std::max(least_max, *std::min_element(worst[t], worst[t] + 4));
        detail::Palette<3> p;
        detail::bc1_interval_palette(c0, c1, set, p);
        for (float budget : {least_max * 0.5f, least_max * 1.3f + 0.01f, 2.0f}) {
            const float allowed = std::max(budget, least_max);
            // The best over all assignments: texels are independent once the allowance is fixed.
            double best_sq = 0;
            for (int t = 0; t < 16; ++t) {
                double b = INFINITY;
                for (int i = 0; i < 4; ++i)
                    if (worst[t][i] <= allowed * (1 + 1e-6f) + 1e-7f) b = std::min(b, double(ref[t][i]));
                best_sq += b;
            }
            const detail::Selection s = detail::select_indices(p, src, false, INFINITY, budget);
            ASSERT_NEAR(s.sum_sq, best_sq, 1e-6 * best_sq + 1e-9) << "case " << k << " budget " << budget;
            ASSERT_LE(s.max_err, allowed * (1 + 1e-6f) + 1e-7f) << "case " << k;
            if (budget < least_max) { ASSERT_NEAR(s.max_err, least_max, 1e-6f) << "case " << k; } // unreachable: the least max, as before
        }
    }
}

// Four blocks of docs/images/ndf_hzd_weather.png (a panel edge: 8 white texels beside 8 greys
// from 5 to 68 of 255), encoded within the bound the bench uses there (42 of 255, its
// unbounded max error), take the squared-error optimum among grey endpoint pairs: a brute
// force over all 64 x 64 grey 565 pairs in both modes (bc1_palette, Reference), each texel on
// its least squared error. Version 7 kept the max-error starts' white and darkest endpoints,
// the greys on the 1/3 entry: 4-7x this optimum (0.24-0.30 against 0.04-0.06).
TEST(Bc1, BoundedPanelEdgeReachesTheGreyPairOptimum) {
    const int greys_of[4][8] = {{42, 51, 61, 66, 62, 61, 34, 18}, {50, 53, 59, 51, 37, 20, 9, 13}, {45, 51, 61, 68, 11, 31, 30, 55}, {52, 47, 59, 58, 20, 17, 7, 5}};
    BlockOptions o;
    o.decoders = kReferenceOnly;
    o.max_error = 42.0f / 255.0f;
    std::vector<uint16_t> greys;
    for (int r = 0; r < 32; ++r)
        for (int g = 2 * r; g <= 2 * r + 1; ++g) greys.push_back(uint16_t((r << 11) | (g << 5) | r));
    for (const auto& gv : greys_of) {
        float src[48];
        for (int t = 0; t < 16; ++t)
            for (int c = 0; c < 3; ++c) src[3 * t + c] = (t < 8 ? float(gv[t]) : 255.0f) / 255.0f;
        double brute = 1e30;
        for (uint16_t c0 : greys)
            for (uint16_t c1 : greys) {
                float pal[4][3];
                bc1_palette(c0, c1, Decoder::Reference, pal);
                brute = std::min(brute, least_squared_error(pal, 4, src, o.max_error)); // 3-colour mode: entry 3 is black
            }
        uint8_t blk[8];
        const BlockResult r = encode_bc1_block(src, o, blk);
        float e, over;
        double sq;
        check_rgb(blk, kReferenceOnly, src, e, over, sq);
        ASSERT_LE(e, o.max_error + 1e-6f);
        ASSERT_NEAR(sq, r.sum_sq, 1e-6 + 1e-6 * r.sum_sq);
        std::printf("panel edge (greys %d..%d): squared error %.4f, grey-pair brute force %.4f\n", *std::min_element(gv, gv + 8), *std::max_element(gv, gv + 8), sq,
                    brute);
        EXPECT_LE(sq, 1.05 * brute);
    }
}

// Given a loose bound, a block of two clusters (a light one beside a darker colour) gets at
// most the squared error of the plain two-cluster answer: each cluster's mean rounded to 565
// as an endpoint (4 colours), each texel on its least squared error (bc1_palette, Reference;
// computed here, not by the encoder). A guard on the least-squares steps: version 7 passed it
// too (the weather map's loss, docs/PERFORMANCE.md, is in blocks of more than two clusters).
TEST(Bc1, BoundedTwoClustersAtMostTheClusterMeans) {
    BlockOptions o;
    o.decoders = kReferenceOnly;
    o.max_error = 1.0f; // no constraint: the squared error decides
    auto q565 = [](const double m[3]) {
        const int r = int(std::lround(std::clamp(m[0], 0.0, 1.0) * 31)), g = int(std::lround(std::clamp(m[1], 0.0, 1.0) * 63)),
                  b = int(std::lround(std::clamp(m[2], 0.0, 1.0) * 31));
        return uint16_t((r << 11) | (g << 5) | b);
    };
    uint64_t state = 0x9E3779B97F4A7C15ull;
    auto rnd = [&] { state = state * 6364136223846793005ull + 1442695040888963407ull; return double(state >> 11) / double(1ull << 53); };
    int worse = 0, blocks = 0;
    double worst = 0, enc_total = 0, two_total = 0;
    for (int k = 0; k < 400; ++k) {
        float src[48];
        double light[3], dark[3];
        for (int c = 0; c < 3; ++c) { light[c] = 0.85 + 0.15 * rnd(); dark[c] = 0.05 + 0.45 * rnd(); }
        const int n_light = 2 + int(rnd() * 12);
        double m0[3] = {0, 0, 0}, m1[3] = {0, 0, 0};
        for (int t = 0; t < 16; ++t) {
            const bool is_light = t < n_light;
            for (int c = 0; c < 3; ++c) {
                const double v = std::clamp((is_light ? light[c] : dark[c]) + 0.03 * (rnd() - 0.5), 0.0, 1.0);
                src[3 * t + c] = float(v);
                (is_light ? m0 : m1)[c] += v / (is_light ? n_light : 16 - n_light);
            }
        }
        uint16_t c0 = q565(m0), c1 = q565(m1);
        if (c0 < c1) std::swap(c0, c1);
        float pal[4][3];
        bc1_palette(c0, c1, Decoder::Reference, pal);
        const double two = least_squared_error(pal, c0 > c1 ? 4 : 3, src);
        uint8_t blk[8];
        const BlockResult r = encode_bc1_block(src, o, blk);
        float e, over;
        double sq;
        check_rgb(blk, kReferenceOnly, src, e, over, sq);
        ASSERT_NEAR(sq, r.sum_sq, 1e-6 + 1e-6 * r.sum_sq);
        if (sq > two * 1.0001 + 1e-9) ++worse;
        worst = std::max(worst, sq / two);
        enc_total += sq;
        two_total += two;
        ++blocks;
    }
    std::printf("BC1 bounded, two clusters: %d of %d blocks above the cluster means' squared error (worst %.2fx), total %.3f of theirs\n", worse,
                blocks, worst, enc_total / two_total);
    EXPECT_LE(worst, 1.05);
}

// Given a bound, the encoder spends it on the squared error: every block stays within the
// bound under every decoder (independent decode), and in all the squared error is lower
// than the max-error-first objective's, which a bound at the unbounded result's own max
// error would not change if the bound were ignored.
TEST(Bc1, BoundSpentOnSquaredError) {
    BlockOptions free_o, bound_o;
    free_o.decoders = bound_o.decoders = kAllDecoders;
    double free_sq = 0, bound_sq = 0;
    int within = 0;
    for (int k = 0; k < 1000; ++k) {
        float src[48];
        rgb_block(uint64_t(k) * 13 + 2, src);
        uint8_t blk[8];
        const BlockResult u = encode_bc1_block(src, free_o, blk);
        bound_o.max_error = u.max_error * 1.25f; // room above the least max error found
        const BlockResult b = encode_bc1_block(src, bound_o, blk);
        float e, over;
        double sq;
        check_rgb(blk, kAllDecoders, src, e, over, sq);
        ASSERT_LE(e, b.max_error + 1e-6f) << k;
        ASSERT_NEAR(sq, b.sum_sq, 1e-6 + 1e-6 * b.sum_sq) << k;
        if (b.max_error <= bound_o.max_error) ++within;
        free_sq += u.sum_sq;
        bound_sq += b.sum_sq;
    }
    std::printf("BC1 normal bounded at 1.25x the unbounded block max: squared error %.4f of max-first's\n", bound_sq / free_sq);
    EXPECT_EQ(within, 1000); // the unbounded result itself was within every bound
    EXPECT_LT(bound_sq, 0.97 * free_sq) << "bounded " << bound_sq << " vs max-first " << free_sq;
}

TEST(Bc1, OneSidedHoldsForEveryDecoderOnSmoothBlocks) {
    BlockOptions o;
    o.one_sided_below = true;
    o.decoders = kAllDecoders;
    int ok = 0;
    for (int k = 0; k < kRandomBlocks / 10; ++k) {
        float src[48];
        rgb_block(uint64_t(k) * 7, src);
        uint8_t blk[8];
        BlockResult r = encode_bc1_block(src, o, blk);
        float e, over;
        double sq;
        check_rgb(blk, kAllDecoders, src, e, over, sq);
        if (r.one_sided_ok) { ASSERT_LE(over, 0.0f) << k; ++ok; }
    }
    EXPECT_GT(ok, kRandomBlocks / 20);
}

TEST(Bc1, DecoderModelsStayWithinConformantTolerance) {
    for (int k = 0; k < 20000; ++k) {
        const uint16_t c0 = uint16_t(unit(k, 1) * 65536), c1 = uint16_t(unit(k, 2) * 65536);
        float ref[4][3];
        bc1_palette(c0, c1, Decoder::Reference, ref);
        for (Decoder d : {Decoder::Nvidia, Decoder::Amd, Decoder::Tool8, Decoder::Tool8Round}) {
            float v[4][3];
            bc1_palette(c0, c1, d, v);
            for (int i = 0; i < 4; ++i)
                for (int c = 0; c < 3; ++c) ASSERT_LE(std::fabs(v[i][c] - ref[i][c]), bc1_conformant_tolerance(ref[0][c], ref[1][c]) + 1e-6f) << decoder_name(d) << " " << c0 << " " << c1;
        }
    }
}

TEST(Bc1, PublishedInterpolationValues) {
    // White (0xFFFF) and black (0x0000), 4-colour mode: index 2 = 2/3 white.
    float n[4][3], a[4][3], t[4][3], r[4][3];
    bc1_palette(0xFFFF, 0x0000, Decoder::Nvidia, n);
    bc1_palette(0xFFFF, 0x0000, Decoder::Amd, a);
    bc1_palette(0xFFFF, 0x0000, Decoder::Tool8, t);
    bc1_palette(0xFFFF, 0x0000, Decoder::Reference, r);
    EXPECT_FLOAT_EQ(r[2][0], 2.0f / 3.0f);
    EXPECT_FLOAT_EQ(t[2][0], 170.0f / 255.0f);           // (2*255)/3
    EXPECT_FLOAT_EQ(a[2][0], 171.0f / 255.0f);           // (255*43 + 32)/64
    EXPECT_FLOAT_EQ(n[2][0], float((62 * 22) / 8) / 255.0f); // ((2*31)*22)/8 = 170
    EXPECT_FLOAT_EQ(n[2][1], float((256 * 255 - 255 / 4 + 128 - 255 * 80) / 256) / 255.0f);
}

TEST(Bc1Scalar, WeightsReproduceNubisConstantsForEightBitDecoders) {
    ScalarUnpack u = bc1_scalar_unpack(kAllDecoders);
    EXPECT_FLOAT_EQ(u.weights[0], 1.0f);
    EXPECT_NEAR(u.weights[1], 0.03529415f, 1e-7f);
    EXPECT_NEAR(u.weights[2], 0.00069204f, 1e-8f);
    ScalarUnpack ref = bc1_scalar_unpack(kReferenceOnly);
    EXPECT_NEAR(ref.weights[1], 1.0f / 31.0f, 1e-7f); // largest float step between levels
    EXPECT_NEAR(ref.weights[2], 1.0f / 31.0f / 63.0f, 1e-8f);
    EXPECT_LT(ref.endpoint_step, 1.0f / 60000.0f); // ~16-bit endpoint precision
}

void run_scalar(DecoderSet set, bool one_sided, Quality q, int blocks, double* mean_under, const ScalarUnpack* custom = nullptr) {
    ScalarUnpack u = custom ? *custom : bc1_scalar_unpack(set);
    BlockOptions o;
    o.decoders = set;
    o.one_sided_below = one_sided;
    o.quality = q;
    double under = 0;
    for (int k = 0; k < blocks; ++k) {
        float src[16];
        scalar_block(uint64_t(k) + 31, 0, 1, src);
        uint8_t blk[8];
        BlockResult r = encode_bc1_scalar_block(src, u, o, blk);
        ASSERT_TRUE(r.one_sided_ok);
        for (Decoder d : decoders_in(set)) {
            float v[16];
            decode_bc1_scalar_block(blk, d, u, v);
            const bool black3 = (blk[0] | (blk[1] << 8)) <= (blk[2] | (blk[3] << 8));
            for (int t = 0; t < 16; ++t) {
                const int idx = (blk[4 + t / 4] >> (2 * (t % 4))) & 3;
                float tol = 0;
                if (d == Decoder::Conformant && !(black3 && idx == 3)) {
                    float ep[4][3];
                    bc1_palette(uint16_t(blk[0] | (blk[1] << 8)), uint16_t(blk[2] | (blk[3] << 8)), Decoder::Reference, ep);
                    for (int c = 0; c < 3; ++c) tol += u.weights[size_t(c)] * bc1_conformant_tolerance(ep[0][c], ep[1][c]);
                }
                ASSERT_LE(std::fabs(v[t] - src[t]) + tol, r.max_error + 1e-6f) << k << " " << decoder_name(d);
                if (one_sided) { ASSERT_LE(v[t] + tol, src[t]) << k << " " << decoder_name(d); }
                if (d == Decoder::Reference) under += src[t] - v[t];
            }
        }
    }
    if (mean_under) *mean_under = under / (16.0 * blocks);
}

TEST(Bc1Scalar, RandomBlocksAllDecoders) { run_scalar(kAllDecoders, false, Quality::Normal, kRandomBlocks, nullptr); }
TEST(Bc1Scalar, RandomBlocksOneSidedAllDecoders) {
    double under = 0;
    run_scalar(kAllDecoders, true, Quality::Normal, kRandomBlocks / 2, &under);
    RecordProperty("mean_under_estimate", std::to_string(under));
    std::printf("bc1-scalar one-sided (all decoders), mixed blocks: mean under-estimate %.6f\n", under);
}
TEST(Bc1Scalar, RandomBlocksOneSidedReferenceOnly) { run_scalar(kReferenceOnly, true, Quality::Best, kRandomBlocks / 20, nullptr); }

// Weights other than bc1_scalar_unpack's use privately built palette tables (not the
// shared per-set ones): the bounds must hold the same way.
TEST(Bc1Scalar, CustomWeightsKeepTheBounds) {
    ScalarUnpack u = bc1_scalar_unpack(kAllDecoders);
    u.weights = {1.0f, 0.04f, 0.0009f};
    u.max_value = u.weights[0] + u.weights[1] + u.weights[2];
    run_scalar(kAllDecoders, true, Quality::Normal, 200, nullptr, &u);
    run_scalar(kAllDecoders, false, Quality::Fast, 200, nullptr, &u);
}

TEST(Bc1Scalar, ConstantBlockReachesEndpointPrecision) {
    for (DecoderSet set : {kReferenceOnly, kAllDecoders}) {
        ScalarUnpack u = bc1_scalar_unpack(set);
        BlockOptions o;
        o.decoders = set;
        o.one_sided_below = true;
        for (int k = 0; k < 500; ++k) {
            float src[16];
            std::fill(src, src + 16, float(unit(k, 9)));
            uint8_t blk[8];
            BlockResult r = encode_bc1_scalar_block(src, u, o, blk);
            // One endpoint step, plus the widening of the bounds to exact arithmetic (2^-21
            // relative, on the endpoint's upper bound and on its lower one).
            if (set == kReferenceOnly) { ASSERT_LE(r.max_error, u.endpoint_step * 1.001f + 1e-7f + 2.0f * src[0] / 2097152.0f) << src[0]; }
        }
    }
}

// Flat blocks are answered from the last flat block this thread encoded when colour and
// options repeat (bc1_encode.cpp, FlatMemo). Encoding a sequence with runs of flat
// colours, options switching between equal colours, and non-flat blocks in between must
// give what each block gives alone on a fresh thread (an empty memo).
TEST(Bc1, FlatBlockMemoEqualsAFreshSearch) {
    std::vector<std::array<float, 48>> blocks;
    auto flat = [&](float r, float g, float b) { blocks.push_back(test::flat_rgb_block(r, g, b)); };
    for (int k = 0; k < 40; ++k) {
        const float r = float(unit(uint64_t(k), 1)), g = float(unit(uint64_t(k), 2)), b = float(unit(uint64_t(k), 3));
        flat(r, g, b);
        flat(r, g, b);
        if (k % 3 == 0) { // a non-flat block between two flat ones of the same colour
            std::array<float, 48> a;
            for (int i = 0; i < 48; ++i) a[size_t(i)] = float(unit(uint64_t(k), 10 + uint64_t(i)));
            blocks.push_back(a);
            flat(r, g, b);
        }
        if (k % 5 == 0) flat(r, g, std::nextafter(b, 2.0f)); // one ulp off: a different colour
    }
    std::vector<BlockOptions> opts(4);
    opts[1].max_error = 8.0f / 255.0f;
    opts[2].decoders = kReferenceOnly;
    opts[3].one_sided_below = true;
    for (size_t i = 0; i < blocks.size(); ++i) {
        for (size_t oi = 0; oi < opts.size(); ++oi) { // every block under each option set in turn: same colour, options changing
            const BlockOptions& o = opts[(i + oi) % opts.size()];
            uint8_t a[8], b[8];
            const BlockResult ra = encode_bc1_block(blocks[i].data(), o, a);
            BlockResult rb;
            std::thread([&] { rb = encode_bc1_block(blocks[i].data(), o, b); }).join();
            ASSERT_EQ(std::memcmp(a, b, 8), 0) << "block " << i << " options " << (i + oi) % opts.size();
            ASSERT_EQ(std::memcmp(&ra.max_error, &rb.max_error, 4), 0) << "block " << i;
            ASSERT_EQ(std::memcmp(&ra.sum_sq, &rb.sum_sq, 8), 0) << "block " << i;
            ASSERT_EQ(ra.one_sided_ok, rb.one_sided_ok) << "block " << i;
        }
    }
}

} // namespace
} // namespace atlas::compress

// Vertical profile LUT vs its analytic form; 2.5D bake vs the formulas.
#include "atlas/ndf/bake.h"
#include "atlas/ndf/ndf_set.h"
#include "atlas/ndf/vertical_profile.h"

#include "atlas/core/error.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

using namespace atlas;
using namespace atlas::ndf;

TEST(VerticalProfile, AnalyticShapes) {
    VerticalProfile p;
    p.validate();
    // At the type nodes the blend is exactly that type's gradient.
    for (int i = 0; i < 4; ++i) {
        const auto& g = p.types[size_t(i)];
        for (double f : {0.0, 0.03, 0.2, 0.5, 0.9, 1.0}) {
            const double expect_b = smoothstep(g.b0, g.b1, f), expect_t = 1 - smoothstep(g.t0, g.t1, f);
            EXPECT_NEAR(p.bottom(i / 3.0, f), expect_b, 1e-12);
            EXPECT_NEAR(p.top(i / 3.0, f), expect_t, 1e-12);
            EXPECT_NEAR(p.density(i / 3.0, f), expect_b * expect_t, 1e-12);
        }
    }
    // Stratus is thin: empty above 0.25; cumulonimbus fills most of the height.
    EXPECT_EQ(p.density(0, 0.3), 0.0);
    EXPECT_GT(p.density(1, 0.7), 0.99);
    // Extremes stay finite and in range.
    for (double t : {-1e30, -1.0, double(NAN), 0.5, 2.0, 1e30})
        for (double f : {-1e30, double(NAN), 0.5, 1e30}) {
            const double v = p.split(t, t, f);
            EXPECT_TRUE(std::isfinite(v));
            EXPECT_GE(v, 0.0);
            EXPECT_LE(v, 1.0);
        }
    VerticalProfile bad = p;
    bad.types[2].t0 = 0.05; // top before bottom
    EXPECT_THROW(bad.validate(), Error);
}

TEST(VerticalProfile, LutWithinItsStatedErrorAndConverges) {
    VerticalProfile p;
    double prev = INFINITY;
    for (int n : {16, 32, 64, 128}) {
        Field2D lut = build_profile_lut(p, n / 4 * 3 + 1, n, nullptr);
        const double err = profile_lut_max_error(lut, p);
        EXPECT_GT(err, 0.0);
        EXPECT_LT(err, prev * 0.6) << n; // second order in the height step
        prev = err;
        // Random points (not on the evaluation grid) stay within the stated error (+ a small margin).
        std::mt19937 rng(n);
        std::uniform_real_distribution<double> u(0, 1);
        double worst = 0;
        for (int i = 0; i < 20000; ++i) {
            const double t = u(rng), f = u(rng);
            worst = std::max(worst, std::abs(sample_profile_lut(lut, 2, t, f) - p.density(t, f)));
            worst = std::max(worst, std::abs(sample_profile_lut(lut, 0, t, f) - p.bottom(t, f)));
            worst = std::max(worst, std::abs(sample_profile_lut(lut, 1, t, f) - p.top(t, f)));
        }
        EXPECT_LE(worst, err * 1.25 + 1e-6) << n;
    }
    EXPECT_LT(prev, 0.02); // 97 x 128 texels (stratus rises within 5 % of the height)
    EXPECT_THROW(build_profile_lut(p, 1, 16, nullptr), Error);
}

TEST(NdfBake, PointwiseEqualToTheFormulas) {
    const Box2d box{{{0, 0}}, {{800, 600}}};
    Field2D set = make_ndf_set({{8, 6}}, box, 1000, 3000, nullptr);
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> u(0, 1);
    for (size_t i = 0; i < set.voxel_count(); ++i) {
        set.channel(Coverage)[i] = u(rng);
        set.channel(TopType)[i] = u(rng);
        set.channel(BottomType)[i] = u(rng);
        set.channel(MinHeight)[i] = 500 + 1000 * u(rng);
        set.channel(MaxHeight)[i] = 2000 + 2000 * u(rng);
    }
    set.channel(MaxHeight)[5] = set.channel(MinHeight)[5]; // degenerate envelope: empty column
    VerticalProfile p;
    const Box3d vb{{{0, 0, 0}}, {{800, 600, 5000}}};
    for (BakeFormula formula : {BakeFormula::VerticalProfile, BakeFormula::Envelope}) {
        Field3D v = bake_ndf_set(set, formula, p, {{8, 6, 50}}, vb, nullptr);
        int nonzero = 0;
        for (int k = 0; k < 50; ++k)
            for (int y = 0; y < 6; ++y)
                for (int x = 0; x < 8; ++x) {
                    const double z = (k + 0.5) * 100;
                    const double lo = set.at(MinHeight, x, y), hi = set.at(MaxHeight, x, y), cov = set.at(Coverage, x, y);
                    double expect = 0;
                    if (hi > lo && z >= lo && z <= hi) {
                        const double f = (z - lo) / (hi - lo);
                        expect = formula == BakeFormula::Envelope
                                     ? cov * f * f * std::pow(1 - f, 1.5)
                                     : cov * p.bottom(set.at(BottomType, x, y), f) * p.top(set.at(TopType, x, y), f);
                    }
                    ASSERT_FLOAT_EQ(v.at(0, x, y, k), float(expect)) << x << " " << y << " " << k;
                    nonzero += expect > 0;
                }
        EXPECT_GT(nonzero, 100);
        for (int k = 0; k < 50; ++k) EXPECT_EQ(v.at(0, 5, 0, k), 0.0f);
    }
}

TEST(NdfBake, ExtremeExtentsAndCoverage) {
    VerticalProfile p;
    for (double extent : {1.0, 1e6}) {
        const Box2d box{{{0, 0}}, {{extent, extent}}};
        for (float cov : {0.0f, 1.0f}) {
            Field2D set = make_ndf_set({{1, 1}}, box, 0.1 * extent, 0.5 * extent, nullptr);
            set.channel(Coverage)[0] = cov;
            Field3D v = bake_ndf_set(set, BakeFormula::VerticalProfile, p, {{1, 1, 64}}, {{{0, 0, 0}}, {{extent, extent, extent}}}, nullptr);
            for (float d : v.channel(0)) {
                ASSERT_TRUE(std::isfinite(d));
                ASSERT_GE(d, 0.0f);
                ASSERT_LE(d, cov);
            }
        }
    }
    Field2D notset({{2, 2}}, 3, {{{0, 0}}, {{1, 1}}});
    EXPECT_THROW(bake_ndf_set(notset, BakeFormula::Envelope, p, {{2, 2, 2}}, {{{0, 0, 0}}, {{1, 1, 1}}}, nullptr), Error);
}

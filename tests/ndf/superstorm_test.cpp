// Superstorm stencil and vortex rings.
#include "atlas/ndf/ndf_set.h"
#include "atlas/ndf/superstorm.h"

#include "atlas/core/error.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

using namespace atlas;
using namespace atlas::ndf;

namespace {
Field2D random_set(Vec2i res, Box2d box) {
    Field2D set = make_ndf_set(res, box, 1500, 4000, nullptr);
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u(0, 1);
    for (int c : {int(Coverage), int(Type), int(TopType), int(BottomType), int(Precipitation), int(SuperstormCoverage)})
        for (float& v : set.channel(c)) v = u(rng);
    return set;
}
} // namespace

TEST(Superstorm, CentreExactBeyondRadiusUnchanged) {
    const Box2d box{{{0, 0}}, {{10000, 10000}}};
    // 101 texels: texel 50's centre is exactly the map centre.
    Field2D set = random_set({{101, 101}}, box);
    SuperstormStencil s;
    s.center = set.texel_center(50, 50);
    s.radius = 3000;
    s.coverage = 0.95;
    s.blend = 1.0;
    Field2D out = apply_superstorm(set, s, nullptr);
    const float c0 = set.at(Coverage, 50, 50);
    EXPECT_EQ(out.at(Coverage, 50, 50), float(std::max(double(c0), 0.95)));
    EXPECT_EQ(out.at(Type, 50, 50), 1.0f);
    EXPECT_EQ(out.at(TopType, 50, 50), 1.0f);
    EXPECT_EQ(out.at(BottomType, 50, 50), 1.0f);
    EXPECT_EQ(out.at(SuperstormCoverage, 50, 50), 1.0f);
    EXPECT_EQ(out.at(MinHeight, 50, 50), float(s.min_height));
    EXPECT_EQ(out.at(MaxHeight, 50, 50), float(s.max_height));
    int inside = 0;
    for (int y = 0; y < 101; ++y)
        for (int x = 0; x < 101; ++x) {
            const double r = length(set.texel_center(x, y) - s.center);
            for (int c = 0; c < ChannelCount; ++c) {
                if (r >= s.radius) {
                    ASSERT_EQ(out.at(c, x, y), set.at(c, x, y)) << x << " " << y << " " << c;
                }
                ASSERT_TRUE(std::isfinite(out.at(c, x, y)));
            }
            if (r < s.radius) {
                ++inside;
                EXPECT_GE(out.at(Coverage, x, y), set.at(Coverage, x, y)); // raised, never lowered
                EXPECT_LE(out.at(MinHeight, x, y), out.at(MaxHeight, x, y) + 1e-3);
            }
        }
    EXPECT_GT(inside, 1000);
    // Half blend at the centre: exactly halfway.
    s.blend = 0.5;
    Field2D half = apply_superstorm(set, s, nullptr);
    EXPECT_FLOAT_EQ(half.at(Type, 50, 50), float(lerp(double(set.at(Type, 50, 50)), 1.0, 0.5)));
}

TEST(Superstorm, BlendZeroIsBitIdentical) {
    const Box2d box{{{0, 0}}, {{10000, 10000}}};
    Field2D set = random_set({{64, 64}}, box);
    SuperstormStencil s;
    s.center = {{5000, 5000}};
    s.blend = 0;
    Field2D out = apply_superstorm(set, s, nullptr);
    EXPECT_TRUE(out == set);
    s.blend = 1e-3; // and any blend changes it
    EXPECT_FALSE(apply_superstorm(set, s, nullptr) == set);
}

TEST(Superstorm, BadInput) {
    const Box2d box{{{0, 0}}, {{1000, 1000}}};
    Field2D set = make_ndf_set({{8, 8}}, box, 0, 1, nullptr);
    SuperstormStencil s;
    s.radius = 0;
    EXPECT_THROW(apply_superstorm(set, s, nullptr), Error);
    s.radius = -5;
    EXPECT_THROW(validate(s), Error);
    s.radius = 100;
    s.min_height = 5000;
    s.max_height = 4000;
    try {
        validate(s);
        FAIL();
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("min_height"), std::string::npos);
    }
    s.min_height = 100;
    s.center = {{5000, 5000}};
    EXPECT_FALSE(stencil_touches(s, box));
    s.center = {{1050, 500}};
    EXPECT_TRUE(stencil_touches(s, box));
    EXPECT_THROW(make_vortex_rings(1000, 3, {100, 100, 300}, 0.2, 1, 0), Error);
    EXPECT_THROW(make_vortex_rings(1000, 3, {100, 50, 300}, 0.2, 1, 0), Error);
    EXPECT_THROW(make_vortex_rings(1000, 3, {100, 300}, 0.2, 1, 0), Error);
    EXPECT_THROW(make_vortex_rings(1000, 2, {100, 3000}, 0.2, 1, 0), Error);
}

TEST(Superstorm, VortexRings) {
    auto rings = make_vortex_rings(6000, 6, {}, 0.25, 0.6, 0.5);
    ASSERT_EQ(rings.size(), 6u);
    for (size_t i = 0; i < rings.size(); ++i) {
        EXPECT_DOUBLE_EQ(rings[i].outer, 1000.0 * double(i + 1));
        if (i) {
            EXPECT_LT(rings[i].speed, rings[i - 1].speed); // slower outward
            EXPECT_EQ(rings[i].inner, rings[i - 1].outer);
        }
    }
    const std::string json = vortex_rings_json({{1, 2}}, 6000, 0.25, rings);
    EXPECT_NE(json.find("\"rings\": [{\"index\": 0"), std::string::npos);
    EXPECT_NE(json.find("\"index\": 5"), std::string::npos);
    const Box2d box{{{-8000, -8000}}, {{8000, 8000}}};
    Field2D map = vortex_ring_map({{160, 160}}, box, {{0, 0}}, rings, 0.25, nullptr);
    for (int y = 0; y < 160; ++y)
        for (int x = 0; x < 160; ++x) {
            const double r = length(map.texel_center(x, y));
            const float idx = map.at(0, x, y), b = map.at(1, x, y);
            ASSERT_GE(b, 0.0f);
            ASSERT_LE(b, 1.0f);
            if (r > 6000 + 250) {
                ASSERT_EQ(idx, -1.0f);
            } else if (b == 0.0f && r < 6000) {
                ASSERT_EQ(idx, float(int(r / 1000))) << r;
            }
        }
}

TEST(Superstorm, VortexRingTableHoldsTheSidecar) {
    const auto rings = make_vortex_rings(6000, 4, {1000, 2500, 4000, 6000}, 0.3, 0.8, 0.4);
    const Field2D t = vortex_ring_table({{500, -700}}, 6000, 0.3, rings);
    ASSERT_EQ(t.width(), 4);
    ASSERT_EQ(t.height(), 1);
    EXPECT_DOUBLE_EQ(0.5 * (t.bounds().min[0] + t.bounds().max[0]), 500.0);
    EXPECT_DOUBLE_EQ(0.5 * (t.bounds().min[1] + t.bounds().max[1]), -700.0);
    EXPECT_DOUBLE_EQ(0.5 * (t.bounds().max[0] - t.bounds().min[0]), 6000.0);
    for (int i = 0; i < 4; ++i) {
        const auto& r = rings[size_t(i)];
        EXPECT_EQ(t.at(t.find_channel("inner"), i, 0), float(r.inner));
        EXPECT_EQ(t.at(t.find_channel("outer"), i, 0), float(r.outer));
        EXPECT_EQ(t.at(t.find_channel("speed"), i, 0), float(r.speed));
        EXPECT_EQ(t.at(t.find_channel("skew"), i, 0), float(r.skew));
        EXPECT_EQ(t.at(t.find_channel("overlap_end"), i, 0), float(r.outer + 0.3 * (r.outer - r.inner)));
    }
    EXPECT_THROW(vortex_ring_table({{0, 0}}, 6000, 0.3, {}), Error);
}

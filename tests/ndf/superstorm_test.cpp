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

TEST(Superstorm, PlumeReachesDownwindOnly) {
    // stretch 3 toward +y (wind_direction 90): the footprint reaches 3 radii
    // downwind, one radius upwind and across; beyond that the map is unchanged.
    const Box2d box{{{0, 0}}, {{20000, 20000}}};
    Field2D set = random_set({{101, 101}}, box);
    SuperstormStencil s;
    s.center = set.texel_center(50, 25);
    s.radius = 2000;
    s.stretch = 3;
    s.wind_direction = 90;
    const Field2D out = apply_superstorm(set, s, nullptr);
    const Vec2d texel = set.voxel_size();
    auto changed = [&](Vec2d p) {
        const int x = int((p[0] - box.min[0]) / texel[0]), y = int((p[1] - box.min[1]) / texel[1]);
        return out.at(Type, x, y) != set.at(Type, x, y);
    };
    EXPECT_TRUE(changed(s.center + Vec2d{{0, 5000}}));   // 2.5 radii downwind: inside the plume
    EXPECT_FALSE(changed(s.center + Vec2d{{0, -2600}})); // 1.3 radii upwind: outside
    EXPECT_FALSE(changed(s.center + Vec2d{{2600, 0}}));  // 1.3 radii across: outside
    EXPECT_FALSE(changed(s.center + Vec2d{{0, 6400}}));  // 3.2 radii downwind: outside
    EXPECT_TRUE(stencil_touches(s, Box2d{{{9000, 10000}}, {{11000, 11000}}})); // the plume's tip reaches 11 km
    // stretch 1 is the disc, bit-identical whatever the wind direction.
    s.stretch = 1;
    const Field2D disc = apply_superstorm(set, s, nullptr);
    s.wind_direction = 0;
    EXPECT_TRUE(apply_superstorm(set, s, nullptr) == disc);
}

TEST(Superstorm, SheetHasAFlatTopAndARisingUnderside) {
    const Box2d box{{{0, 0}}, {{10000, 10000}}};
    Field2D set = random_set({{101, 101}}, box);
    SuperstormStencil s;
    s.center = set.texel_center(50, 50);
    s.radius = 4000;
    s.core = 0.3;
    s.distortion = 0;
    s.sheet = true;
    s.min_height = 8500;
    s.max_height = 11000;
    s.coverage = 0.9;
    const Field2D out = apply_superstorm(set, s, nullptr);
    double previous_base = 0;
    for (int x = 50; x < 101; ++x) {
        const double r = length(set.texel_center(x, 50) - s.center);
        if (r >= s.radius) {
            EXPECT_EQ(out.at(MaxHeight, x, 50), set.at(MaxHeight, x, 50)) << x; // the map beyond the rim
            continue;
        }
        EXPECT_EQ(out.at(MaxHeight, x, 50), 11000.0f) << x; // flat top
        const double base = out.at(MinHeight, x, 50);
        EXPECT_GE(base, previous_base) << x; // the underside rises toward the rim
        EXPECT_GE(base, 8500.0 - 1e-3);
        EXPECT_LE(base, 11000.0);
        // The map's own cloud in the column is replaced by the sheet's.
        const double w = 1.0 - smoothstep(s.core * s.radius, s.radius, r);
        EXPECT_NEAR(out.at(Coverage, x, 50), 0.9 * w, 1e-6) << x;
        previous_base = base;
    }
    EXPECT_EQ(out.at(MinHeight, 50, 50), 8500.0f); // full thickness in the core
}

TEST(Superstorm, HeightCoreWidensTheFlatBaseAndEdgeNoiseZeroIsRound) {
    const Box2d box{{{0, 0}}, {{10000, 10000}}};
    Field2D set = random_set({{101, 101}}, box);
    SuperstormStencil s;
    s.center = set.texel_center(50, 50);
    s.radius = 4000;
    s.core = 0.2;
    s.distortion = 0;
    const Field2D plain = apply_superstorm(set, s, nullptr);
    s.height_core = s.core; // the same core: the same bytes
    EXPECT_TRUE(apply_superstorm(set, s, nullptr) == plain);
    s.height_core = 0.75;
    const Field2D wide = apply_superstorm(set, s, nullptr);
    // 0.6 radii out the base is the storm's with height_core 0.75, not yet with core 0.2.
    const int x = 50 + int(std::lround(0.6 * 4000 / set.voxel_size()[0]));
    EXPECT_EQ(wide.at(MinHeight, x, 50), float(s.min_height));
    EXPECT_NE(plain.at(MinHeight, x, 50), float(s.min_height));
    EXPECT_EQ(wide.at(Coverage, x, 50), plain.at(Coverage, x, 50)); // coverage keeps `core`
    s.height_core = -1;
    s.edge_noise = 0.8; // a ragged footprint: some texels differ, none beyond the radius
    const Field2D ragged = apply_superstorm(set, s, nullptr);
    EXPECT_FALSE(ragged == plain);
    for (int y = 0; y < 101; ++y)
        for (int xx = 0; xx < 101; ++xx)
            if (length(set.texel_center(xx, y) - s.center) >= s.radius) {
                ASSERT_EQ(ragged.at(Coverage, xx, y), set.at(Coverage, xx, y));
            }
}

TEST(Superstorm, TowerWallTopAndBaseOptions) {
    // A tower chained after a sheet of coverage 1 (the shipped superstorm's order).
    const Box2d box{{{0, 0}}, {{20000, 20000}}};
    Field2D set = random_set({{201, 201}}, box);
    SuperstormStencil sheet;
    sheet.center = set.texel_center(100, 100);
    sheet.radius = 9000;
    sheet.core = 0.8;
    sheet.distortion = 0;
    sheet.sheet = true;
    sheet.min_height = 8500;
    sheet.max_height = 11000;
    const Field2D under = apply_superstorm(set, sheet, nullptr);
    SuperstormStencil s;
    s.center = sheet.center;
    s.radius = 6000;
    s.core = 0.4;
    s.height_core = 0.75;
    s.min_height = 800;
    s.max_height = 12300;
    const Field2D plain = apply_superstorm(under, s, nullptr);
    // Every new option at its default: the same bytes as before them.
    s.wall_noise = 0, s.base_relief = 0, s.own_coverage = false;
    ASSERT_TRUE(apply_superstorm(under, s, nullptr) == plain);
    const Vec2d texel = set.voxel_size();
    auto at = [&](const Field2D& f, int c, double r, double angle) {
        const Vec2d p = s.center + Vec2d{{r * std::cos(angle), r * std::sin(angle)}};
        return double(f.at(c, int(p[0] / texel[0]), int(p[1] / texel[1])));
    };
    // Without own coverage the tower's wall keeps the sheet's solid coverage; with it, the tower's own.
    const double wall = 0.7 * s.radius;
    EXPECT_GT(at(plain, Coverage, wall, 0.3), 0.99);
    s.own_coverage = true;
    const Field2D own = apply_superstorm(under, s, nullptr);
    EXPECT_LT(at(own, Coverage, wall, 0.3), 0.9);
    EXPECT_EQ(at(own, Coverage, 0, 0), 1.0); // the core is still full
    for (int y = 0; y < 201; ++y)
        for (int x = 0; x < 201; ++x)
            if (length(set.texel_center(x, y) - s.center) >= s.radius) {
                ASSERT_EQ(own.at(Coverage, x, y), under.at(Coverage, x, y)); // unchanged beyond the radius
            }
    // wall_noise: where the base leaves 800 m, swept round the tower, varies with the direction.
    auto edge_spread = [&](const Field2D& f) {
        std::vector<double> edge;
        for (int a = 0; a < 64; ++a) {
            const double t = 6.283185307179586 * a / 64;
            double r = 0;
            while (r < s.radius && at(f, MinHeight, r, t) < 4000) r += texel[0] * 0.5;
            edge.push_back(r);
        }
        double mean = 0, var = 0;
        for (double e : edge) mean += e / double(edge.size());
        for (double e : edge) var += (e - mean) * (e - mean) / double(edge.size());
        return std::sqrt(var);
    };
    s.own_coverage = false;
    s.distortion = 0;
    s.edge_noise = 0;
    const Field2D round = apply_superstorm(under, s, nullptr);
    s.wall_noise = 0.8;
    const Field2D lumpy = apply_superstorm(under, s, nullptr);
    EXPECT_LT(edge_spread(round), texel[0]);
    EXPECT_GT(edge_spread(lumpy), 2 * texel[0]);
    // base_relief: the base rises in patches by at most the relief, never above the top.
    s.wall_noise = 0;
    s.base_relief = 600;
    const Field2D relief = apply_superstorm(under, s, nullptr);
    double lo = 1e9, hi = -1e9;
    for (int a = 0; a < 360; ++a)
        for (double r = 0; r < 0.7 * s.radius; r += 200) {
            const double b = at(relief, MinHeight, r, a * 0.0174533);
            lo = std::min(lo, b), hi = std::max(hi, b);
        }
    EXPECT_EQ(lo, 800.0);
    EXPECT_GT(hi, 800.0 + 300);
    EXPECT_LE(hi, 800.0 + 600 + 1e-3);
    // Out of range: refused by name.
    s.wall_noise = 1.0;
    try {
        validate(s);
        FAIL();
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("wall_noise"), std::string::npos) << e.what();
    }
    s.wall_noise = 0;
    s.base_relief = -1;
    EXPECT_THROW(validate(s), Error);
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

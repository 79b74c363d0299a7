// Cumulus anatomy from coarse shapes (issue 41): billows grow on the exposed,
// up- and out-facing surface at several scales, towers rise, nothing grows
// below the base; detail type and density scale follow the pack's anatomy.
#include "atlas/core/error.h"
#include "atlas/volume/cumulus.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

using namespace atlas;

namespace {
Points ball(double x, double y, double z, double r) {
    Points p;
    p.positions.push_back({{float(x), float(y), float(z)}});
    p.attributes["radius"] = {float(r)};
    return p;
}

double dist(const Vec3f& a, const Vec3f& b) {
    return std::sqrt(double(a[0] - b[0]) * (a[0] - b[0]) + double(a[1] - b[1]) * (a[1] - b[1]) + double(a[2] - b[2]) * (a[2] - b[2]));
}
} // namespace

TEST(Billows, GenerationsGrowOnTheUpperExposedSurfaceAboveTheBase) {
    volume::BillowSpec s;
    s.levels = 2;
    s.children = 16;
    s.base_height = 150; // the parent's centre is at 200: its lower part is below the base
    s.min_radius = 4;
    const Points out = volume::billow_spheres(ball(0, 0, 200, 100), s);
    const auto& r = out.attributes.at("radius");
    ASSERT_GT(out.positions.size(), 10u);
    EXPECT_EQ(out.positions[0], (Vec3f{{0, 0, 200}}));
    int gen1 = 0, gen2 = 0;
    double up = 0;
    for (size_t i = 1; i < out.positions.size(); ++i) {
        const Vec3f& p = out.positions[i];
        EXPECT_GE(p[2] - 0.5 * r[i], 150 - 1e-3) << i; // nothing below the base
        if (std::fabs(r[i] - 45) <= 45 * 0.31) ++gen1, up += (p[2] - 200) / dist(p, out.positions[0]);
        else ++gen2;
        // Every sphere's outer side is exposed: its centre is not buried deep in the parent.
        EXPECT_GT(dist(p, out.positions[0]), 0.3 * 100) << i;
    }
    EXPECT_GT(gen1, 3);
    EXPECT_GT(gen2, gen1); // the second generation is larger in number
    EXPECT_GT(up / gen1, 0.3); // facing up on average
    // Deterministic.
    EXPECT_EQ(volume::billow_spheres(ball(0, 0, 200, 100), s), out);
}

TEST(Billows, TowersRiseFromTheHighestSphereAndTaper) {
    Points shape = ball(0, 0, 200, 100);
    const Points hi = ball(300, 0, 260, 80);
    shape.positions.push_back(hi.positions[0]);
    shape.attributes["radius"].push_back(80);
    volume::BillowSpec s;
    s.levels = 0;
    s.towers = 1;
    s.tower_height = 200;
    const Points out = volume::billow_spheres(shape, s);
    ASSERT_GT(out.positions.size(), 4u);
    const auto& r = out.attributes.at("radius");
    double top = 0;
    for (size_t i = 2; i < out.positions.size(); ++i) {
        EXPECT_LT(r[i], r[i - 1] + 1e-3);
        EXPECT_GT(out.positions[i][2], out.positions[i - 1][2] - 1e-3);
        EXPECT_LT(std::fabs(out.positions[i][0] - 300), 100); // on the higher sphere
        top = std::max(top, double(out.positions[i][2]) + r[i]);
    }
    EXPECT_GT(top, 260 + 80 + 100);
    EXPECT_LE(top, 260 + 80 + 200 + 1e-3);
}

TEST(Billows, BadSettingsAndShapesAreNamed) {
    volume::BillowSpec s;
    s.ratio = 1.5;
    EXPECT_THROW(volume::billow_spheres(ball(0, 0, 0, 10), s), Error);
    s = {};
    Points bad = ball(0, 0, 0, 10);
    bad.attributes["radius"][0] = -1;
    try {
        volume::billow_spheres(bad, s);
        FAIL();
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("shape point 0"), std::string::npos) << e.what();
    }
    bad.attributes.clear();
    EXPECT_THROW(volume::billow_spheres(bad, s), Error);
}

// A sphere's SDF: detail type 1 on top, 0 underneath and deep inside; density
// scale from the floor at the base to 1 past the ramp; 0 in both beyond outside_voxels.
TEST(CumulusPaint, UpFacingTopsBillowyUndersidesWispyDensityRisesFromTheBase) {
    const Vec3i res{{40, 40, 40}};
    Field3D sdf(res, 1, Box3d{{{-200, -200, 0}}, {{200, 200, 400}}}, {"sdf"});
    for (int z = 0; z < 40; ++z)
        for (int y = 0; y < 40; ++y)
            for (int x = 0; x < 40; ++x) {
                const Vec3d p = sdf.voxel_center(x, y, z);
                sdf.at(0, x, y, z) = float(std::sqrt(p[0] * p[0] + p[1] * p[1] + (p[2] - 200) * (p[2] - 200)) - 150);
            }
    volume::CumulusPaintSpec s;
    s.base_height = 50;
    s.billow_depth = 60;
    s.skirt = 20;
    s.scale_floor = 0.1;
    s.scale_ramp = 200;
    const auto c = volume::cumulus_channels(sdf, s);
    auto at = [&](const Field3D& f, double x, double y, double z) {
        const Vec3d v = f.voxel_size();
        return f.at(0, int((x + 200) / v[0]), int((y + 200) / v[1]), int(z / v[2]));
    };
    EXPECT_GT(at(c.detail_type, 0, 0, 345), 0.9);  // just under the top
    EXPECT_LT(at(c.detail_type, 0, 0, 55), 0.05);  // the underside
    EXPECT_LT(at(c.detail_type, 0, 0, 200), 0.05); // deep inside
    EXPECT_GT(at(c.detail_type, 0, 0, 375), 0.9);  // outside above the top (2.5 voxels out): spread outward
    EXPECT_NEAR(at(c.density_scale, 0, 0, 45), 0.1, 1e-6);
    EXPECT_NEAR(at(c.density_scale, 0, 0, 375), 1.0, 1e-6);
    // Past outside_voxels (3) both channels are 0: 4.5 voxels above the top, and a corner.
    EXPECT_EQ(at(c.detail_type, 0, 0, 395), 0.0f);
    EXPECT_EQ(at(c.density_scale, 0, 0, 395), 0.0f);
    EXPECT_EQ(c.density_scale.at(0, 0, 0, 39), 0.0f);
    s.outside_voxels = 1e9; // paint everywhere
    const auto everywhere = volume::cumulus_channels(sdf, s);
    EXPECT_NEAR(at(everywhere.density_scale, 0, 0, 395), 1.0, 1e-6);
    EXPECT_NEAR(everywhere.density_scale.at(0, 0, 0, 39), 1.0, 1e-6);
    for (size_t i = 0; i < sdf.voxel_count(); ++i) // the same values wherever both paint
        if (sdf.channel(0)[i] <= 30.0f) {
            ASSERT_EQ(everywhere.density_scale.channel(0)[i], c.density_scale.channel(0)[i]);
            ASSERT_EQ(everywhere.detail_type.channel(0)[i], c.detail_type.channel(0)[i]);
        }
    s.outside_voxels = -1;
    EXPECT_THROW(volume::cumulus_channels(sdf, s), Error);
    s.outside_voxels = 3;
    const float mid = at(c.density_scale, 0, 0, 155);
    EXPECT_GT(mid, 0.2);
    EXPECT_LT(mid, 0.9);
    for (float v : c.detail_type.channel(0)) ASSERT_TRUE(v >= 0 && v <= 1);
    s.billow_depth = 0;
    EXPECT_THROW(volume::cumulus_channels(sdf, s), Error);
}

// A capsule's SDF filled with spheres: the deepest ball first (the capsule's
// radius), a stack along its axis, every voxel deep enough claimed, and the
// balls inside the shape (issue 41: a solver's cloud becomes coarse spheres).
TEST(SdfSpheres, FillAShapeDeepestFirstAndStayInside) {
    const Vec3i res{{32, 32, 64}};
    Field3D sdf(res, 1, Box3d{{{0, 0, 0}}, {{320, 320, 640}}}, {"sdf"});
    auto capsule = [](const Vec3d& p) {
        const double z = std::clamp(p[2], 200.0, 440.0);
        return std::sqrt((p[0] - 160) * (p[0] - 160) + (p[1] - 160) * (p[1] - 160) + (p[2] - z) * (p[2] - z)) - 80;
    };
    for (int z = 0; z < 64; ++z)
        for (int y = 0; y < 32; ++y)
            for (int x = 0; x < 32; ++x) sdf.at(0, x, y, z) = float(capsule(sdf.voxel_center(x, y, z)));
    volume::SphereFillSpec s;
    s.min_radius = 20;
    const Points p = volume::spheres_from_sdf(sdf, s);
    const auto& r = p.attributes.at("radius");
    ASSERT_GE(p.positions.size(), 3u);
    EXPECT_GT(r[0], 70); // the capsule's own radius, less half a voxel
    for (size_t i = 1; i < r.size(); ++i) EXPECT_LE(r[i], r[i - 1] + 1e-3); // deepest first
    double zmin = 1e9, zmax = -1e9;
    for (size_t i = 0; i < r.size(); ++i) {
        const Vec3f& c = p.positions[i];
        EXPECT_LE(capsule({{c[0], c[1], c[2]}}) + r[i], 10.0) << i; // inside, within a voxel
        if (r[i] > 60) zmin = std::min(zmin, double(c[2])), zmax = std::max(zmax, double(c[2]));
    }
    EXPECT_LT(zmin, 260); // a stack along the axis, end to end
    EXPECT_GT(zmax, 380);
    EXPECT_EQ(volume::spheres_from_sdf(sdf, s), p); // deterministic
    s.cover = 0;
    EXPECT_THROW(volume::spheres_from_sdf(sdf, s), Error);
}

// NDF generators and operators: properties against independent references.
#include "atlas/ndf/generators.h"
#include "atlas/ndf/ndf_set.h"
#include "atlas/ndf/operators.h"

#include "atlas/core/error.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "atlas/core/field_math.h"
#include "atlas/noise/value_noise.h"

using namespace atlas;
using namespace atlas::ndf;

namespace {
const Box2d kBox{{{0, 0}}, {{1000, 1000}}};

// Mean |difference| across the wrap seam (last column to first, last row to
// first) over the mean |difference| across interior lines every `cell`
// texels. The seam of a lattice noise lies on a lattice line, where the
// quintic fade is flat, so it is compared with interior lattice lines.
double seam_ratio(const Field2D& f, int cell) {
    double seam = 0, inner = 0;
    int ns = 0, ni = 0;
    for (int y = 0; y < f.height(); ++y) {
        seam += std::abs(f.at(0, f.width() - 1, y) - f.at(0, 0, y));
        ++ns;
        for (int x = cell; x < f.width(); x += cell) inner += std::abs(f.at(0, x, y) - f.at(0, x - 1, y)), ++ni;
    }
    for (int x = 0; x < f.width(); ++x) {
        seam += std::abs(f.at(0, x, f.height() - 1) - f.at(0, x, 0));
        ++ns;
        for (int y = cell; y < f.height(); y += cell) inner += std::abs(f.at(0, x, y) - f.at(0, x, y - 1)), ++ni;
    }
    return (seam / ns) / (inner / ni);
}
} // namespace

TEST(NdfGenerators, LinearGradientMatchesProjection) {
    Field2D g = gradient_linear({{64, 32}}, kBox, {{100, 0}}, {{900, 0}}, nullptr);
    for (int y = 0; y < 32; y += 7)
        for (int x = 0; x < 64; ++x) {
            const double px = g.texel_center(x, y)[0];
            EXPECT_NEAR(g.at(0, x, y), std::clamp((px - 100) / 800, 0.0, 1.0), 1e-6);
        }
    EXPECT_THROW(gradient_linear({{4, 4}}, kBox, {{1, 1}}, {{1, 1}}, nullptr), Error);
    EXPECT_THROW(gradient_linear({{4, 4}}, kBox, {{NAN, 1}}, {{1, 1}}, nullptr), Error);
}

TEST(NdfGenerators, RadialGradientCentreAndRim) {
    Field2D g = gradient_radial({{101, 101}}, kBox, {{500, 500}}, 300, nullptr);
    for (int x = 0; x < 101; ++x) {
        const double r = std::abs(g.texel_center(x, 50)[0] - 500);
        EXPECT_NEAR(g.at(0, x, 50), std::max(0.0, 1 - r / 300), 1e-6);
    }
    EXPECT_THROW(gradient_radial({{4, 4}}, kBox, {{0, 0}}, 0, nullptr), Error);
    EXPECT_THROW(gradient_radial({{4, 4}}, kBox, {{0, 0}}, -1, nullptr), Error);
}

TEST(NdfGenerators, ShapesInsideFalloffOutside) {
    auto shapes = parse_shapes("ellipse 500 500 200 100 0.8 100; stroke 20 1 0 0 900 1000 900; polygon 0.5 0 0 0 200 0 0 200");
    ASSERT_EQ(shapes.size(), 3u);
    Field2D f = paint_shapes({{100, 100}}, kBox, shapes, nullptr);
    auto at_world = [&](double x, double y) { return f.at(0, int(x / 10), int(y / 10)); };
    EXPECT_FLOAT_EQ(at_world(505, 505), 0.8f);       // ellipse centre
    EXPECT_FLOAT_EQ(at_world(505, 905), 1.0f);       // on the stroke
    EXPECT_FLOAT_EQ(at_world(55, 55), 0.5f);         // inside the triangle
    EXPECT_FLOAT_EQ(at_world(185, 185), 0.0f);       // outside the triangle, hard edge
    const float mid = at_world(755, 505);             // 50 m outside the ellipse's x rim: in the falloff
    EXPECT_GT(mid, 0.0f);
    EXPECT_LT(mid, 0.8f);
    EXPECT_FLOAT_EQ(at_world(905, 505), 0.0f);       // beyond the falloff
    EXPECT_THROW(parse_shapes("ellipse 1 2 3"), Error);
    EXPECT_THROW(parse_shapes("blob 1 2 3"), Error);
    EXPECT_THROW(parse_shapes("ellipse 0 0 0 1 1 0"), Error);
    EXPECT_THROW(parse_shapes("stroke 1 1 0 5 5"), Error);
    EXPECT_THROW(parse_shapes("polygon 1 0 0 0 1 x 2 2"), Error);
}

TEST(NdfGenerators, NoiseTilesWithoutSeamAndIsDeterministic) {
    for (int octaves : {1, 4}) {
        Field2D n = noise2d({{128, 128}}, kBox, {{4, 4}}, octaves, 0.5, 7, nullptr);
        const double ratio = seam_ratio(n, 32);
        EXPECT_LT(ratio, 2.0) << octaves;
        EXPECT_GT(ratio, 0.5) << octaves; // a seam-free map is neither smoother nor rougher at the wrap
        auto s = channel_stats(n.channel(0));
        EXPECT_GE(s.min, 0.0);
        EXPECT_LE(s.max, 1.0);
        EXPECT_GT(s.max - s.min, 0.2);
        EXPECT_TRUE(n == noise2d({{128, 128}}, kBox, {{4, 4}}, octaves, 0.5, 7, nullptr));
    }
    // A non-tileable map (a gradient) has a seam: the test measure can fail.
    EXPECT_GT(seam_ratio(gradient_linear({{64, 64}}, kBox, {{0, 0}}, {{1000, 0}}, nullptr), 16), 10.0);
    EXPECT_THROW(noise2d({{4, 4}}, kBox, {{0, 1}}, 1, 0.5, 0, nullptr), Error);
}

TEST(NdfOperators, WrappedBlurAndWarpKeepTiling) {
    Field2D n = noise2d({{64, 64}}, kBox, {{4, 4}}, 3, 0.5, 3, nullptr);
    Field2D b = blur(n, 2.0, WrapMode::Wrap, nullptr);
    EXPECT_LT(seam_ratio(b, 16), 2.0);
    // Blur preserves the mean under wrap (a normalised kernel on a torus).
    EXPECT_NEAR(channel_stats(b.channel(0)).mean, channel_stats(n.channel(0)).mean, 1e-4);
    Field2D w = noise2d({{64, 64}}, kBox, {{2, 2}}, 1, 0.5, 9, nullptr);
    Field2D warped = domain_warp(n, w, 40, WrapMode::Wrap, nullptr);
    EXPECT_LT(seam_ratio(warped, 16), 2.0);
    EXPECT_FALSE(warped == n);
    // Zero amount is an identity (samples at texel centres).
    Field2D same = domain_warp(n, w, 0, WrapMode::Wrap, nullptr);
    for (size_t i = 0; i < n.voxel_count(); ++i) ASSERT_NEAR(same.channel(0)[i], n.channel(0)[i], 1e-6);
    Field2D copy = blur(n, 0, WrapMode::Clamp, nullptr);
    EXPECT_TRUE(copy == n);
}

TEST(NdfOperators, CurveIsMonotoneAndInterpolates) {
    Curve c = Curve::parse("0 0; 0.3 0.1; 0.6 0.9; 1 1");
    EXPECT_DOUBLE_EQ(c(0.3), 0.1);
    EXPECT_DOUBLE_EQ(c(0.6), 0.9);
    EXPECT_DOUBLE_EQ(c(-5), 0.0);
    EXPECT_DOUBLE_EQ(c(5), 1.0);
    EXPECT_DOUBLE_EQ(c(NAN), 0.0);
    double prev = -1;
    for (int i = 0; i <= 1000; ++i) {
        const double v = c(i / 1000.0);
        EXPECT_GE(v, prev - 1e-12);
        EXPECT_LE(v, 1.0 + 1e-12);
        prev = v;
    }
    EXPECT_THROW(Curve::parse("0 0; 0 1"), Error);
    EXPECT_THROW(Curve::parse("0 0"), Error);
    EXPECT_THROW(Curve::parse("0 0; 1"), Error);
}

TEST(NdfOperators, ThresholdAndComposite) {
    Field2D g = gradient_linear({{100, 1}}, kBox, {{0, 0}}, {{1000, 0}}, nullptr);
    Field2D t = threshold(g, 0.5, 0, nullptr);
    for (int x = 0; x < 100; ++x) EXPECT_EQ(t.at(0, x, 0), g.at(0, x, 0) >= 0.5f ? 1.0f : 0.0f);
    Field2D s = threshold(g, 0.5, 0.2, nullptr);
    for (int x = 0; x < 100; ++x) EXPECT_NEAR(s.at(0, x, 0), smoothstep(0.4, 0.6, g.at(0, x, 0)), 1e-6);

    Field2D a = noise2d({{32, 32}}, kBox, {{2, 2}}, 2, 0.5, 1, nullptr);
    Field2D b = noise2d({{32, 32}}, kBox, {{2, 2}}, 2, 0.5, 2, nullptr);
    Field2D m = gradient_linear({{32, 32}}, kBox, {{0, 0}}, {{1000, 0}}, nullptr);
    for (auto [name, op] : std::vector<std::pair<std::string, std::function<float(float, float)>>>{
             {"add", [](float x, float y) { return x + y; }},
             {"multiply", [](float x, float y) { return x * y; }},
             {"max", [](float x, float y) { return std::max(x, y); }},
             {"min", [](float x, float y) { return std::min(x, y); }},
             {"over", [](float x, float y) { return y + x * (1 - y); }},
             {"lerp", [](float, float y) { return y; }}}) {
        Field2D r = composite(a, b, &m, parse_composite_op(name), 1.0, nullptr);
        Field2D full = composite(a, b, nullptr, parse_composite_op(name), 1.0, nullptr);
        for (size_t i = 0; i < a.voxel_count(); ++i) {
            const float x = a.channel(0)[i], y = b.channel(0)[i], k = m.channel(0)[i];
            ASSERT_NEAR(full.channel(0)[i], op(x, y), 1e-6) << name;
            ASSERT_NEAR(r.channel(0)[i], x + (op(x, y) - x) * k, 1e-5) << name;
        }
    }
    EXPECT_TRUE(composite(a, b, nullptr, CompositeOp::Add, 0.0, nullptr) == a);
    EXPECT_THROW(parse_composite_op("screen"), Error);
    Field2D small({{8, 8}}, 1, kBox);
    EXPECT_THROW(composite(a, small, nullptr, CompositeOp::Add, 1, nullptr), Error);
}

TEST(NdfSet, ChannelsAndPrecipitationRule) {
    Field2D set = make_ndf_set({{64, 1}}, kBox, 1500, 4000, nullptr);
    EXPECT_NO_THROW(check_ndf_set(set));
    EXPECT_EQ(set.channel_name(MaxHeight), "max_height");
    // Precipitation ramps 0..1 across the map, coverage 0.2, type 0.
    for (int x = 0; x < 64; ++x) {
        set.at(Precipitation, x, 0) = float(x / 63.0);
        set.at(Coverage, x, 0) = 0.2f;
    }
    PrecipitationRule rule;
    Field2D r = apply_precipitation_rule(set, rule, nullptr);
    for (int x = 0; x < 64; ++x) {
        const double p = x / 63.0;
        if (p <= rule.rain_start) {
            EXPECT_EQ(r.at(Coverage, x, 0), 0.2f);
            EXPECT_EQ(r.at(Type, x, 0), 0.0f);
        }
    }
    EXPECT_FLOAT_EQ(r.at(Type, 63, 0), 1.0f); // rain certain: cumulonimbus
    EXPECT_GE(r.at(Coverage, 63, 0), 0.7f);   // and coverage >= 70 %
    EXPECT_THROW(make_ndf_set({{4, 4}}, kBox, 5000, 4000, nullptr), Error);
    EXPECT_THROW(apply_precipitation_rule(set, PrecipitationRule{0.8, 0.8, 0.7, 1.0}, nullptr), Error);
    EXPECT_THROW(apply_precipitation_rule(Field2D({{4, 4}}, 8, kBox), rule, nullptr), Error);
}

TEST(NdfGenerators, NoiseMatchesTheNoiseLibrary) {
    // noise2d interpolates library lattice values row by row; it must agree
    // with the library's own evaluation at the texel centres.
    const Vec2i res{{40, 24}};
    const Vec3i period{{5, 3, 1}};
    Field2D n = noise2d(res, kBox, {{5, 3}}, 1, 0.5, 17, nullptr);
    for (int y = 0; y < res[1]; ++y)
        for (int x = 0; x < res[0]; ++x) {
            const double lx = (x + 0.5) * period[0] / res[0], ly = (y + 0.5) * period[1] / res[1];
            ASSERT_NEAR(n.at(0, x, y), noise::value_noise(lx, ly, 0.0, period, 17), 2e-6) << x << " " << y;
        }
}

TEST(NdfGenerators, ShapeFalloffReachesPastTheLongRadius) {
    // A tall ellipse (ry > rx): bounding-box culling must not cut the falloff
    // beside the long axis. At 45 degrees outside the edge, within the falloff.
    const auto shapes = parse_shapes("ellipse 500 500 20 300 1 200");
    const Field2D f = paint_shapes({{200, 200}}, kBox, shapes, nullptr);
    int in_falloff = 0;
    for (int y = 0; y < 200; ++y)
        for (int x = 0; x < 200; ++x) {
            const Vec2d p = f.texel_center(x, y);
            const double dx = std::abs(p[0] - 500);
            if (dx > 20 + 200 + 300) {
                ASSERT_EQ(f.at(0, x, y), 0.0f); // beyond every possible reach
            }
            if (f.at(0, x, y) > 0 && f.at(0, x, y) < 1) ++in_falloff;
        }
    EXPECT_GT(in_falloff, 500);
    // Straight beside the centre, 100 m outside the 20 m half-width: inside the falloff.
    EXPECT_GT(f.at(0, int(620 / 5), int(500 / 5)), 0.0f);
    EXPECT_LT(f.at(0, int(620 / 5), int(500 / 5)), 1.0f);
}

// Extremes and thread-count determinism of the ndf algorithms.
#include "atlas/ndf/cone_map.h"
#include "atlas/ndf/distance_map.h"
#include "atlas/ndf/generators.h"
#include "atlas/ndf/ndf_set.h"
#include "atlas/ndf/operators.h"
#include "atlas/ndf/superstorm.h"

#include "atlas/core/error.h"
#include "atlas/core/memory.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>

using namespace atlas;
using namespace atlas::ndf;

namespace {
// A small recipe touching every row/block-parallel algorithm.
std::vector<Field2D> recipe(int n) {
    const Box2d box{{{0, 0}}, {{8000, 8000}}};
    std::vector<Field2D> out;
    Field2D a = noise2d({{n, n}}, box, {{4, 4}}, 4, 0.5, 1, nullptr);
    Field2D w = noise2d({{n, n}}, box, {{2, 2}}, 2, 0.5, 2, nullptr);
    out.push_back(domain_warp(a, w, 300, WrapMode::Wrap, nullptr));
    out.push_back(blur(out.back(), 1.5, WrapMode::Wrap, nullptr));
    out.push_back(apply_curve(out.back(), Curve::parse("0 0; 0.5 0.3; 1 1"), nullptr));
    out.push_back(threshold(out.back(), 0.4, 0.1, nullptr));
    out.push_back(composite(a, w, &out.back(), CompositeOp::Over, 0.8, nullptr));
    Field2D set = make_ndf_set({{n, n}}, box, 1000, 3000, nullptr);
    std::copy(a.channel(0).begin(), a.channel(0).end(), set.channel(Coverage).begin());
    std::copy(w.channel(0).begin(), w.channel(0).end(), set.channel(Precipitation).begin());
    set = apply_precipitation_rule(set, {}, nullptr);
    SuperstormStencil s;
    s.center = {{4000, 4000}};
    s.radius = 3000;
    out.push_back(apply_superstorm(set, s, nullptr));
    ConeMapOptions opt;
    opt.robust = true;
    opt.texel_size = 8000.0 / n;
    out.push_back(cone_map(out.back(), MaxHeight, opt, nullptr));
    return out;
}
} // namespace

TEST(NdfExtremes, SameBytesForAnyThreadCount) {
    std::vector<Field2D> one, many;
    {
        tbb::global_control gc(tbb::global_control::max_allowed_parallelism, 1);
        one = recipe(96);
    }
    many = recipe(96);
    ASSERT_EQ(one.size(), many.size());
    for (size_t i = 0; i < one.size(); ++i) EXPECT_TRUE(one[i] == many[i]) << "step " << i;
}

TEST(NdfExtremes, TinyAndHugeMapsStayFinite) {
    for (double extent : {1.0, 1e6}) {
        const Box2d box{{{0, 0}}, {{extent, extent}}};
        for (int n : {1, 3}) {
            std::vector<Field2D> maps;
            maps.push_back(noise2d({{n, n}}, box, {{1, 1}}, 3, 0.5, 0, nullptr));
            maps.push_back(gradient_linear({{n, n}}, box, {{0, 0}}, {{extent, extent}}, nullptr));
            maps.push_back(gradient_radial({{n, n}}, box, {{0.5 * extent, 0.5 * extent}}, 0.25 * extent, nullptr));
            maps.push_back(paint_shapes({{n, n}}, box, parse_shapes("ellipse 0 0 1 1 1 1e9"), nullptr));
            maps.push_back(blur(maps[0], 10, WrapMode::Clamp, nullptr));
            maps.push_back(blur(maps[0], 10, WrapMode::Wrap, nullptr));
            maps.push_back(domain_warp(maps[0], maps[1], 1e9, WrapMode::Wrap, nullptr));
            maps.push_back(domain_warp(maps[0], maps[1], 1e9, WrapMode::Clamp, nullptr));
            Field2D set = make_ndf_set({{n, n}}, box, 0, extent, nullptr);
            for (float cov : {0.0f, 1.0f}) {
                std::fill(set.channel(Coverage).begin(), set.channel(Coverage).end(), cov);
                SuperstormStencil s;
                s.center = {{0.5 * extent, 0.5 * extent}};
                s.radius = extent;
                s.min_height = 0;
                s.max_height = 2 * extent;
                maps.push_back(apply_superstorm(apply_precipitation_rule(set, {}, nullptr), s, nullptr));
            }
            ConeMapOptions opt;
            opt.texel_size = extent / n;
            maps.push_back(cone_map(maps.back(), MaxHeight, opt, nullptr));
            for (const Field2D& m : maps)
                for (int c = 0; c < m.channels(); ++c)
                    for (float v : m.channel(c)) ASSERT_TRUE(std::isfinite(v)) << extent << " " << n;
            Field3D d = distance_map(maps.back(), 0, 4, 0, extent, 10 * extent, nullptr);
            for (float v : d.channel(0)) ASSERT_TRUE(std::isfinite(v));
        }
    }
}

TEST(NdfExtremes, HugeMapIsRefusedByTheBudget) {
    MemoryBudget small(64ull << 20); // 64 MiB: an 8192^2 NDF set needs 2 GiB
    EXPECT_THROW(make_ndf_set({{8192, 8192}}, {{{0, 0}}, {{1, 1}}}, 0, 1, &small), Error);
    EXPECT_THROW(noise2d({{8192, 8192}}, {{{0, 0}}, {{1, 1}}}, {{1, 1}}, 1, 0.5, 0, &small), Error);
    EXPECT_THROW(make_ndf_set({{0, 4}}, {{{0, 0}}, {{1, 1}}}, 0, 1, nullptr), Error);
    EXPECT_THROW(make_ndf_set({{4, 4}}, {{{0, 0}}, {{0, 1}}}, 0, 1, nullptr), Error);
}

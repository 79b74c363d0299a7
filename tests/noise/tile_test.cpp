// Tileability: every kernel and variant gives the same value at p and at
// p + one tile (lattice coordinate + period) on every axis, 2D and 3D.
#include "noise_test_util.h"

#include "atlas/core/hash.h"
#include "atlas/noise/value_noise.h"

#include <gtest/gtest.h>

#include <cmath>

namespace atlas::noise {
namespace {

using test::all_variants;

std::vector<Vec3d> random_points3(int n, uint32_t seed) {
    std::vector<Vec3d> p;
    for (int i = 0; i < n; ++i)
        p.push_back({{hash_to_unit(hash_coords(seed, i, 0)) * 1.0, hash_to_unit(hash_coords(seed, i, 1)) * 1.0,
                      hash_to_unit(hash_coords(seed, i, 2)) * 1.0}});
    return p;
}

TEST(NoiseTile, EveryKernel3DWrapsOnEveryAxis) {
    const auto pts = random_points3(200, 11);
    for (const auto& [name, spec] : all_variants()) {
        const auto base = sample_noise(spec, std::span<const Vec3d>(pts));
        for (int axis = 0; axis < 3; ++axis)
            for (double shift : {1.0, -2.0}) {
                std::vector<Vec3d> moved = pts;
                for (auto& p : moved) p[axis] += shift; // whole tiles
                const auto v = sample_noise(spec, std::span<const Vec3d>(moved));
                ASSERT_EQ(v.size(), base.size());
                double worst = 0;
                for (size_t i = 0; i < v.size(); ++i) worst = std::max(worst, double(std::fabs(v[i] - base[i])));
                EXPECT_LE(worst, 1e-6) << name << " axis " << axis << " shift " << shift;
            }
    }
}

TEST(NoiseTile, EveryKernel2DWrapsOnEveryAxis) {
    std::vector<Vec2d> pts;
    for (int i = 0; i < 200; ++i) pts.push_back({{hash_to_unit(hash_coords(5, i, 0)), hash_to_unit(hash_coords(5, i, 1))}});
    for (const auto& [name, spec] : all_variants()) {
        const auto base = sample_noise(spec, std::span<const Vec2d>(pts));
        for (int axis = 0; axis < 2; ++axis) {
            std::vector<Vec2d> moved = pts;
            for (auto& p : moved) p[axis] += 3.0;
            const auto v = sample_noise(spec, std::span<const Vec2d>(moved));
            double worst = 0;
            for (size_t i = 0; i < v.size(); ++i) worst = std::max(worst, double(std::fabs(v[i] - base[i])));
            EXPECT_LE(worst, 1e-6) << name << " axis " << axis;
        }
    }
}

// A filled field wraps: the sample one voxel beyond the last equals voxel 0,
// which only holds when the field spans whole tiles.
TEST(NoiseTile, FilledFieldMatchesPointLookupsAndWraps) {
    for (const auto& [name, spec] : test::all_kernels()) {
        const int comps = noise_components(spec.kernel, 3);
        Field3D f({{8, 6, 5}}, comps, Box3d{{{0, 0, 0}}, {{1, 1, 1}}});
        fill_noise(f, 0, spec);
        std::vector<Vec3d> p = {{{(0 + 0.5) / 8, (2 + 0.5) / 6, (3 + 0.5) / 5}}, {{(8 + 0.5) / 8, (2 + 0.5) / 6, (3 + 0.5) / 5}},
                                {{(7 + 0.5) / 8, (5 + 0.5) / 6 - 1.0, (4 + 0.5) / 5 + 1.0}}};
        const auto v = sample_noise(spec, std::span<const Vec3d>(p));
        for (int c = 0; c < comps; ++c) {
            EXPECT_NEAR(v[size_t(c)], f.at(c, 0, 2, 3), 1e-6) << name;
            EXPECT_NEAR(v[size_t(comps + c)], f.at(c, 0, 2, 3), 1e-6) << name;
            EXPECT_NEAR(v[size_t(2 * comps + c)], f.at(c, 7, 5, 4), 1e-6) << name;
        }
    }
}

// Independent reference: the one-octave value kernel is the foundation's
// value_noise (same lattice values, same quintic blend).
TEST(NoiseTile, ValueKernelMatchesValueNoise) {
    NoiseSpec s = test::make(Kernel::Value, 5, 42);
    const auto pts = random_points3(300, 3);
    const auto v = sample_noise(s, std::span<const Vec3d>(pts));
    for (size_t i = 0; i < pts.size(); ++i) {
        const double x = pts[i][0] * s.period[0], y = pts[i][1] * s.period[1], z = pts[i][2] * s.period[2];
        EXPECT_NEAR(v[i], value_noise(x, y, z, s.period, s.seed), 1e-6);
    }
}

} // namespace
} // namespace atlas::noise

// atlas/noise/value_fbm.h against brute-force sums of value_noise() with weights computed
// here from their definition (gain^o / sum gain^k).
#include "atlas/core/error.h"
#include "atlas/core/field.h"
#include "atlas/core/hash.h"
#include "atlas/noise/value_fbm.h"
#include "atlas/noise/value_noise.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <cstring>

using namespace atlas;
using namespace atlas::noise;

namespace {

double weight(int o, int octaves, double gain) {
    double norm = 0;
    for (int k = 0; k < octaves; ++k) norm += std::pow(gain, k);
    return std::pow(gain, o) / norm;
}

TEST(ValueFbm, WeightsFollowTheGain) {
    for (double gain : {0.0, 0.3, 0.5, 1.0}) {
        const ValueFbm f{.octaves = 5, .gain = gain};
        const auto w = fbm_weights(f);
        ASSERT_EQ(w.size(), 5u);
        double sum = 0;
        for (int o = 0; o < 5; ++o) {
            EXPECT_NEAR(w[size_t(o)], weight(o, 5, gain), 1e-7);
            sum += w[size_t(o)];
        }
        EXPECT_NEAR(sum, 1.0, 1e-6);
    }
}

TEST(ValueFbm, RowIsTheWeightedOctaveSum) {
    const ValueFbm f{.octaves = 4, .gain = 0.6, .seed = 11, .seed_step = 77};
    const auto w = fbm_weights(f);
    std::vector<float> out(37), scratch;
    auto place = [](int o) {
        FbmRow r;
        r.period = {{3 << o, 5 << o, 2 << o}};
        r.x0 = 0.25 * (o + 1);
        r.dx = 0.13 * (1 << o);
        r.y = 1.7 * (o + 1);
        r.z = 0.9 + o;
        return r;
    };
    value_fbm_row(out, f, w, place, scratch);
    for (size_t i = 0; i < out.size(); ++i) {
        double ref = 0;
        for (int o = 0; o < 4; ++o) {
            const FbmRow r = place(o);
            ref += weight(o, 4, 0.6) * value_noise(r.x0 + double(i) * r.dx, r.y, r.z, r.period, 11u + uint32_t(o) * 77u);
        }
        EXPECT_NEAR(out[i], ref, 1e-6) << i;
    }
}

TEST(ValueFbm, FieldMatchesBruteForceOnAnyThreadCount) {
    const Vec3i res{{12, 10, 6}}, period{{3, 2, 1}};
    Field3D f(res, 1, Box3d{{{0, 0, 0}}, {{1, 1, 1}}}, {"v"});
    const ValueFbm fbm{.octaves = 3, .gain = 0.5, .seed = 5};
    fill_value_fbm(f, 0, period, fbm);
    for (int z = 0; z < res[2]; ++z)
        for (int y = 0; y < res[1]; ++y)
            for (int x = 0; x < res[0]; ++x) {
                double ref = 0;
                for (int o = 0; o < 3; ++o) {
                    const Vec3i p{{period[0] << o, period[1] << o, period[2] << o}};
                    ref += weight(o, 3, 0.5) * value_noise((x + 0.5) * p[0] / res[0], (y + 0.5) * p[1] / res[1], (z + 0.5) * p[2] / res[2], p,
                                                           5u + uint32_t(o) * 1013u);
                }
                ASSERT_NEAR(f.at(0, x, y, z), ref, 1e-6) << x << " " << y << " " << z;
                ASSERT_GE(f.at(0, x, y, z), -1e-6f);
                ASSERT_LE(f.at(0, x, y, z), 1 + 1e-6f);
            }
    // The same bytes on 1 and 3 threads (rows are fixed work units).
    Field3D one(res, 1, Box3d{{{0, 0, 0}}, {{1, 1, 1}}}, {"v"}), three(res, 1, Box3d{{{0, 0, 0}}, {{1, 1, 1}}}, {"v"});
    tbb::task_arena(1).execute([&] { fill_value_fbm(one, 0, period, fbm); });
    tbb::task_arena(3).execute([&] { fill_value_fbm(three, 0, period, fbm); });
    EXPECT_EQ(0, std::memcmp(one.channel(0).data(), three.channel(0).data(), one.channel(0).size() * sizeof(float)));
    EXPECT_THROW(fill_value_fbm(f, 1, period, fbm), Error);
    EXPECT_THROW(fill_value_fbm(f, 0, period, ValueFbm{.octaves = 0}), Error);
}

TEST(ValueFbm, MapMatchesBruteForceOnBothPaths) {
    // period 2 over 16 texels: coarse octaves take the lattice-row path; period 40 over
    // 8 texels: more than 4 cells per texel, the per-texel path.
    for (const auto& [res, period] : {std::pair{Vec2i{{16, 9}}, Vec2i{{2, 3}}}, std::pair{Vec2i{{8, 5}}, Vec2i{{40, 3}}}}) {
        const ValueFbm fbm{.octaves = 3, .gain = 0.7, .seed = 9};
        std::vector<float> out(size_t(res[0] * res[1]));
        value_fbm_map(out, res, period, fbm);
        for (int y = 0; y < res[1]; ++y)
            for (int x = 0; x < res[0]; ++x) {
                double ref = 0;
                for (int o = 0; o < 3; ++o) {
                    const Vec3i p{{period[0] << o, period[1] << o, 1}};
                    ref += weight(o, 3, 0.7) * value_noise((x + 0.5) * p[0] / res[0], (y + 0.5) * p[1] / res[1], 0.0, p, 9u + uint32_t(o) * 1013u);
                }
                ASSERT_NEAR(out[size_t(y * res[0] + x)], ref, 2e-6) << x << " " << y;
            }
    }
    std::vector<float> wrong(3);
    EXPECT_THROW(value_fbm_map(wrong, Vec2i{{2, 2}}, Vec2i{{1, 1}}, ValueFbm{}), Error);
}

TEST(SmoothValueNoise, HitsTheLatticeAndStaysInRange) {
    for (int i = -3; i < 4; ++i)
        EXPECT_DOUBLE_EQ(smooth_value_noise(4, i, 2 * i, -i), double(hash_to_unit(hash_coords(4, i, 2 * i, -i))));
    for (int i = 0; i < 200; ++i) {
        const double x = -5 + 0.0731 * i, y = 0.37 * i, z = 0.011 * i;
        const double v = smooth_value_noise(4, x, y, z);
        EXPECT_GE(v, 0.0);
        EXPECT_LE(v, 1.0);
        // Smooth: a small step changes it little (bounded slope of the smoothstep blend).
        EXPECT_NEAR(smooth_value_noise(4, x + 1e-6, y, z), v, 1e-5);
    }
}

} // namespace

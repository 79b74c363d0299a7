// Ranges, statistics and the curl's divergence.
#include "noise_test_util.h"

#include "atlas/core/hash.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>

namespace atlas::noise {
namespace {

struct Stats {
    double mean = 0, var = 0, lo = 1e30, hi = -1e30;
    bool finite = true;
};

Stats stats_of(std::span<const float> v) {
    Stats s;
    double sum = 0, sum2 = 0;
    for (float x : v) {
        s.finite = s.finite && std::isfinite(x);
        sum += x;
        sum2 += double(x) * x;
        s.lo = std::min(s.lo, double(x));
        s.hi = std::max(s.hi, double(x));
    }
    s.mean = sum / double(v.size());
    s.var = sum2 / double(v.size()) - s.mean * s.mean;
    return s;
}

// The mean/variance bands of docs/noise.md (one octave, 3D, 32^3 samples of
// a period-8 tile; bands are wide enough for any seed, narrow enough to
// catch a wrong scale or offset).
struct Band {
    double mean_lo, mean_hi, var_lo, var_hi;
};
const std::map<std::string, Band>& bands() {
    static const std::map<std::string, Band> b = {
        {"gradient", {-0.05, 0.05, 0.03, 0.12}},
        {"value", {0.4, 0.6, 0.03, 0.08}},
        {"worley-f1-euclidean", {0.45, 0.6, 0.01, 0.04}},
        {"worley-inverted-f1-euclidean", {0.4, 0.55, 0.01, 0.04}},
        {"worley-f2-f1-euclidean", {0.15, 0.35, 0.01, 0.05}},
        {"perlin-worley", {0.6, 0.85, 0.003, 0.03}},
        {"alligator", {0.08, 0.25, 0.01, 0.05}},
        {"curly-alligator", {0.75, 0.92, 0.01, 0.05}},
        {"curl", {-0.1, 0.1, 0.6, 1.5}},
    };
    return b;
}

TEST(NoiseStats, RangesHoldAndMomentsSitInTheirBands) {
    for (const auto& [name, base] : test::all_variants()) {
        NoiseSpec spec = base;
        spec.period = {{8, 8, 8}};
        const int comps = noise_components(spec.kernel, 3);
        Field3D f({{32, 32, 32}}, comps, Box3d{{{0, 0, 0}}, {{1, 1, 1}}});
        fill_noise(f, 0, spec);
        const ValueRange r = noise_output_range(spec, 3);
        for (int c = 0; c < comps; ++c) {
            const Stats s = stats_of(f.channel(c));
            ASSERT_TRUE(s.finite) << name;
            EXPECT_GE(s.lo, r.lo) << name;
            EXPECT_LE(s.hi, r.hi) << name;
            EXPECT_GT(s.var, 1e-4) << name << ": not constant";
            auto it = bands().find(name);
            if (it != bands().end()) {
                EXPECT_GE(s.mean, it->second.mean_lo) << name;
                EXPECT_LE(s.mean, it->second.mean_hi) << name;
                EXPECT_GE(s.var, it->second.var_lo) << name;
                EXPECT_LE(s.var, it->second.var_hi) << name;
            }
        }
    }
}

// Central differences of the curl field: divergence must be tiny compared to
// the field's own derivatives (analytic derivatives of a C2 potential).
TEST(NoiseStats, CurlIsDivergenceFree) {
    for (int octaves : {1, 3}) {
        NoiseSpec s = test::make(Kernel::Curl, 4, 9);
        s.fractal.octaves = octaves;
        const double h = 1e-4; // in tiles
        double worst_ratio = 0;
        for (int i = 0; i < 200; ++i) {
            const Vec3d p{{hash_to_unit(hash_coords(2, i, 0)), hash_to_unit(hash_coords(2, i, 1)), hash_to_unit(hash_coords(2, i, 2))}};
            std::vector<Vec3d> q;
            for (int a = 0; a < 3; ++a) {
                Vec3d plus = p, minus = p;
                plus[a] += h;
                minus[a] -= h;
                q.push_back(plus);
                q.push_back(minus);
            }
            const auto v = sample_noise(s, std::span<const Vec3d>(q));
            double div = 0, grad2 = 0;
            for (int a = 0; a < 3; ++a) {
                // d/dx in lattice cells: lattice coordinate = p * period.
                const double scale = 1.0 / (2 * h * s.period[a]);
                div += (v[size_t(6 * a + a)] - v[size_t(6 * a + 3 + a)]) * scale;
                for (int c = 0; c < 3; ++c) {
                    const double d = (v[size_t(6 * a + c)] - v[size_t(6 * a + 3 + c)]) * scale;
                    grad2 += d * d;
                }
            }
            worst_ratio = std::max(worst_ratio, std::fabs(div) / std::sqrt(grad2 / 9 + 1e-12));
        }
        EXPECT_LT(worst_ratio, 1e-2) << "octaves " << octaves;
    }
}

TEST(NoiseStats, Curl2DIsDivergenceFree) {
    NoiseSpec s = test::make(Kernel::Curl, 4, 3);
    s.fractal.octaves = 2;
    const double h = 1e-4;
    double worst_ratio = 0;
    for (int i = 0; i < 200; ++i) {
        const Vec2d p{{hash_to_unit(hash_coords(4, i, 0)), hash_to_unit(hash_coords(4, i, 1))}};
        std::vector<Vec2d> q = {{{p[0] + h, p[1]}}, {{p[0] - h, p[1]}}, {{p[0], p[1] + h}}, {{p[0], p[1] - h}}};
        const auto v = sample_noise(s, std::span<const Vec2d>(q));
        const double sx = 1.0 / (2 * h * s.period[0]), sy = 1.0 / (2 * h * s.period[1]);
        const double dxx = (v[0] - v[2]) * sx, dyx = (v[1] - v[3]) * sx, dxy = (v[4] - v[6]) * sy, dyy = (v[5] - v[7]) * sy;
        const double grad = std::sqrt((dxx * dxx + dyx * dyx + dxy * dxy + dyy * dyy) / 4 + 1e-12);
        worst_ratio = std::max(worst_ratio, std::fabs(dxx + dyy) / grad);
    }
    EXPECT_LT(worst_ratio, 1e-2);
}

// The Worley features are one computation seen four ways: F1 <= F2,
// F2-F1 and 1-F1 agree with F1 and F2 wherever nothing was clamped.
TEST(NoiseStats, WorleyFeaturesAreConsistent) {
    for (const char* metric : {"euclidean", "manhattan", "chebyshev"}) {
        std::vector<float> v[4];
        const char* features[4] = {"f1", "f2", "f2-f1", "inverted-f1"};
        std::vector<Vec3d> pts;
        for (int i = 0; i < 500; ++i)
            pts.push_back({{hash_to_unit(hash_coords(8, i, 0)), hash_to_unit(hash_coords(8, i, 1)), hash_to_unit(hash_coords(8, i, 2))}});
        for (int f = 0; f < 4; ++f) {
            NoiseSpec s = test::make(Kernel::Worley, 4, 21);
            s.worley.feature = parse_worley_feature(features[f]);
            s.worley.metric = parse_worley_metric(metric);
            v[f] = sample_noise(s, std::span<const Vec3d>(pts));
        }
        for (size_t i = 0; i < pts.size(); ++i) {
            EXPECT_LE(v[0][i], v[1][i]) << metric;
            EXPECT_NEAR(v[3][i], 1.0f - v[0][i], 1e-6) << metric;
            if (v[1][i] < 1.0f) {
                EXPECT_NEAR(v[2][i], v[1][i] - v[0][i], 1e-6) << metric;
            }
        }
    }
}

// Negative control for the tile tests: a non-integer frequency must NOT
// wrap, so the tile comparison is able to fail.
TEST(NoiseStats, NonIntegerFrequencyDoesNotTile) {
    NoiseSpec s = test::make(Kernel::Gradient, 4, 1);
    s.frequency = 1.37;
    std::vector<Vec3d> p = {{{0.3, 0.4, 0.5}}, {{1.3, 0.4, 0.5}}};
    const auto v = sample_noise(s, std::span<const Vec3d>(p));
    EXPECT_GT(std::fabs(v[0] - v[1]), 1e-4);
}

} // namespace
} // namespace atlas::noise

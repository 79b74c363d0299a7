// @takram/three-clouds layout (atlas/ndf/three_clouds.h): the weather channels by
// cloud type, three-clouds' own weather formula (written here from its
// shaders/clouds.glsl) reading them back, layers against the analytic profile,
// and the shape volume's equalisation.
#include "atlas/core/error.h"
#include "atlas/core/hash.h"
#include "atlas/ndf/ndf_set.h"
#include "atlas/ndf/three_clouds.h"
#include "atlas/ndf/vertical_profile.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

using namespace atlas;
using namespace atlas::ndf;

namespace {

double clamp01(double v) { return std::clamp(v, 0.0, 1.0); }

// three-clouds 0.7.6 sampleWeather(): the weather density of one layer before
// the shape erodes it, at height fraction eta in the layer.
double three_weather_density(double weather, double coverage, double filter_width, double bias, double eta) {
    const double x = std::clamp(2.0 * std::pow(eta, bias) - 1.0, -1.0, 1.0);
    const double height_scale = 1.0 - x * x;
    const double factor = 1.0 - coverage * height_scale;
    const double v = weather * (1.0 - filter_width) + filter_width; // mix(weather, 1, w)
    return clamp01((v - factor) / filter_width);
}

Field2D set_with(const std::vector<std::pair<float, float>>& coverage_type) {
    Field2D s = make_ndf_set({{int(coverage_type.size()), 1}}, {{{0, 0}}, {{double(coverage_type.size()) * 100, 100}}}, 1500, 4000, nullptr);
    for (size_t i = 0; i < coverage_type.size(); ++i) {
        s.at(Coverage, int(i), 0) = coverage_type[i].first;
        s.at(Type, int(i), 0) = coverage_type[i].second;
    }
    return s;
}

Field2D default_lut() { return build_profile_lut(VerticalProfile{}, 97, 128, nullptr); }

} // namespace

TEST(ThreeClouds, WeatherChannelsByType) {
    const Field2D s = set_with({{0.8f, 0.0f}, {0.6f, 1.0f / 3}, {0.5f, 2.0f / 3}, {0.9f, 1.0f}, {0.7f, 1.0f / 6}, {0.4f, 0.25f}, {0.0f, 0.5f}});
    const ThreeCloudsWeather w = three_clouds_weather(s, default_lut(), nullptr);
    ASSERT_EQ(w.weather.channels(), 4);
    for (int x = 0; x < s.width(); ++x) {
        const double c = s.at(Coverage, x, 0), t = s.at(Type, x, 0);
        for (int k = 0; k < 4; ++k) EXPECT_NEAR(w.weather.at(k, x, 0), c * clamp01(2.0 * (1.0 - std::abs(3.0 * t - k))), 1e-6) << x << " " << k;
    }
    // A pure type lands in its own channel only; halfway between two types in both, whole.
    EXPECT_FLOAT_EQ(w.weather.at(2, 2, 0), 0.5f);
    EXPECT_EQ(w.weather.at(1, 2, 0), 0.0f);
    EXPECT_FLOAT_EQ(w.weather.at(0, 4, 0), 0.7f);
    EXPECT_FLOAT_EQ(w.weather.at(1, 4, 0), 0.7f);
    for (const ThreeCloudsLayer& l : w.layers) EXPECT_TRUE(l.used) << l.name;
    EXPECT_DOUBLE_EQ(w.min_height, 1500);
    EXPECT_DOUBLE_EQ(w.max_height, 4000);
    EXPECT_EQ(w.envelope_spread, 0);
}

TEST(ThreeClouds, ThreeCloudsReadsTheChannelBackAtMidLayer) {
    // atlas view sets coverage 1/2 and coverageFilterWidth 1/2: where the
    // shape-altering profile is 1 the weather density is the channel's value,
    // and below it less (the profile rounds the column).
    for (double L = 0; L <= 1.0; L += 0.05) {
        EXPECT_NEAR(three_weather_density(L, 0.5, 0.5, 1.0, 0.5), L, 1e-12) << L;
        EXPECT_LT(three_weather_density(L, 0.5, 0.5, 1.0, 0.05), L + 1e-12) << L;
    }
    // and the bias puts that peak where asked.
    for (double peak : {0.2, 0.38, 0.5, 0.7}) {
        const double b = three_clouds_bias_for_peak(peak);
        double best = -1, at = 0;
        for (int i = 0; i <= 10000; ++i) {
            const double eta = i / 10000.0, x = 2.0 * std::pow(eta, b) - 1.0, hs = 1.0 - x * x;
            if (hs > best) best = hs, at = eta;
        }
        EXPECT_NEAR(at, peak, 2e-3) << peak;
    }
}

TEST(ThreeClouds, LayersSpanTheProfilesHalfMaximum) {
    const VerticalProfile p;
    const Field2D s = set_with({{1.0f, 0.0f}, {1.0f, 1.0f / 3}, {1.0f, 2.0f / 3}, {1.0f, 1.0f}});
    const ThreeCloudsWeather w = three_clouds_weather(s, default_lut(), nullptr);
    for (int k = 0; k < 4; ++k) {
        const double t = k / 3.0;
        // Brute force on the analytic profile (not the LUT the code reads).
        double best = 0;
        for (int i = 0; i <= 20000; ++i) best = std::max(best, p.bottom(t, i / 20000.0) * p.top(t, i / 20000.0));
        double lo = 1, hi = 0;
        for (int i = 0; i <= 20000; ++i) {
            const double f = i / 20000.0;
            if (p.bottom(t, f) * p.top(t, f) >= 0.5 * best) lo = std::min(lo, f), hi = std::max(hi, f);
        }
        const ThreeCloudsLayer& l = w.layers[size_t(k)];
        // The LUT has 128 heights: within a texel and a half of 2500 m.
        EXPECT_NEAR(l.altitude, 1500 + lo * 2500, 30) << l.name;
        EXPECT_NEAR(l.altitude + l.height, 1500 + hi * 2500, 30) << l.name;
        EXPECT_EQ(l.channel, "rgba"[k]);
    }
    EXPECT_LT(w.layers[0].height, w.layers[2].height); // stratus is thinner than cumulus
}

TEST(ThreeClouds, EnvelopeIsTheCoverageWeightedMeanAndItsSpreadIsReported) {
    Field2D s = set_with({{1.0f, 0.5f}, {0.5f, 0.5f}, {0.0f, 0.5f}});
    s.at(MinHeight, 0, 0) = 1000, s.at(MaxHeight, 0, 0) = 3000;
    s.at(MinHeight, 1, 0) = 2500, s.at(MaxHeight, 1, 0) = 6000;
    s.at(MinHeight, 2, 0) = 90000, s.at(MaxHeight, 2, 0) = 99000; // no coverage: not counted
    const ThreeCloudsWeather w = three_clouds_weather(s, default_lut(), nullptr);
    EXPECT_DOUBLE_EQ(w.min_height, (1000 * 1.0 + 2500 * 0.5) / 1.5);
    EXPECT_DOUBLE_EQ(w.max_height, (3000 * 1.0 + 6000 * 0.5) / 1.5);
    EXPECT_DOUBLE_EQ(w.envelope_spread, 6000 - w.max_height);
    EXPECT_FALSE(w.layers[0].used);
}

TEST(ThreeClouds, ShapeIsTheEqualisedDilatedBase) {
    Field3D n({{16, 16, 16}}, 4, {{{0, 0, 0}}, {{1, 1, 1}}}, {"r", "g", "b", "a"}, nullptr);
    std::vector<double> base(n.voxel_count());
    for (int c = 0; c < 4; ++c) {
        auto ch = n.channel(c);
        for (size_t i = 0; i < ch.size(); ++i) ch[i] = float(hash_coords(5 + uint32_t(c), int(i), 0, 0) >> 8) / float(1 << 24);
    }
    for (size_t i = 0; i < base.size(); ++i) {
        const double low = n.channel(1)[i] * 0.625 + n.channel(2)[i] * 0.25 + n.channel(3)[i] * 0.125;
        base[i] = (n.channel(0)[i] + 1.0 - low) / (2.0 - low); // GPU Pro 7's remap(r, low - 1, 1, 0, 1)
    }
    const Field3D s = three_clouds_shape(n, nullptr);
    ASSERT_EQ(s.channels(), 1);
    auto v = s.channel(0);
    // Uniform: each tenth of [0, 1] holds a tenth of the voxels.
    std::vector<int> deciles(10, 0);
    for (float x : v) {
        ASSERT_GE(x, 0.0f);
        ASSERT_LE(x, 1.0f);
        ++deciles[size_t(std::min(9, int(x * 10)))];
    }
    for (int d : deciles) EXPECT_NEAR(d, int(v.size()) / 10, 2);
    // Order-preserving: the fraction that passes remap(d, 1 - shape, 1) is the
    // fraction of the base above Atlas's coverage threshold.
    for (size_t i = 0; i + 1 < base.size(); i += 7) {
        if (base[i] < base[i + 1]) {
            EXPECT_LT(v[i], v[i + 1]) << i;
        }
    }
    const Field3D d = three_clouds_shape_detail(n, nullptr);
    EXPECT_NEAR(d.channel(0)[3], n.channel(0)[3] * 0.625 + n.channel(1)[3] * 0.25 + n.channel(2)[3] * 0.125, 1e-6);
}

TEST(ThreeClouds, AWeatherMapWithoutTypesIsStratus) {
    // A 2.5D preview's weather map as a set: coverage and heights only.
    Field2D m({{2, 1}}, 3, {{{0, 0}}, {{200, 100}}}, {"coverage", "min_height", "max_height"}, nullptr);
    m.at(0, 0, 0) = 0.6f, m.at(1, 0, 0) = 1500, m.at(2, 0, 0) = 4000;
    m.at(0, 1, 0) = 0.0f, m.at(1, 1, 0) = 1500, m.at(2, 1, 0) = 4000;
    const ThreeCloudsWeather w = three_clouds_weather(m, default_lut(), nullptr);
    EXPECT_FLOAT_EQ(w.weather.at(0, 0, 0), 0.6f);
    EXPECT_EQ(w.weather.at(1, 0, 0), 0.0f);
    EXPECT_TRUE(w.layers[0].used);
    EXPECT_FALSE(w.layers[2].used);
}

TEST(ThreeClouds, BadInputIsRefusedByName) {
    const Field2D lut = default_lut();
    Field2D empty = set_with({{0.0f, 0.5f}});
    EXPECT_THROW(three_clouds_weather(empty, lut, nullptr), Error);
    try {
        three_clouds_weather(empty, lut, nullptr);
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("no cloud"), std::string::npos) << e.what();
    }
    EXPECT_THROW(three_clouds_weather(lut, lut, nullptr), Error);                         // no coverage channel
    EXPECT_THROW(three_clouds_weather(set_with({{1.0f, 0.5f}}), set_with({{1.0f, 0.5f}}), nullptr), Error); // not a LUT
    Field3D two({{4, 4, 4}}, 2, {{{0, 0, 0}}, {{1, 1, 1}}}, {}, nullptr);
    EXPECT_THROW(three_clouds_shape(two, nullptr), Error);
    EXPECT_THROW(three_clouds_shape_detail(two, nullptr), Error);
    Field2D one({{4, 4}}, 1, {{{0, 0}}, {{1, 1}}}, {}, nullptr);
    EXPECT_THROW(three_clouds_turbulence(one, nullptr), Error);
}

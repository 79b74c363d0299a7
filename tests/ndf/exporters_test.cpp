// Engine exporters: each layout holds what docs/formats.md says, at probe points.
#include "atlas/core/error.h"
#include "atlas/core/files.h"
#include "atlas/core/hash.h"
#include "atlas/graph/evaluator.h"
#include "atlas/graph/node.h"
#include "atlas/ndf/exporters.h"
#include "atlas/ndf/generators.h"
#include "atlas/ndf/ndf_set.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <numbers>
#include <string>
#include <tuple>
#include <vector>

using namespace atlas;
using namespace atlas::ndf;

namespace {
// A set with hashed random channels; heights straddle the layer, one NaN (sets of 2x2 and more).
Field2D random_set(Vec2i res, Box2d box) {
    Field2D s = make_ndf_set(res, box, 0, 1, nullptr);
    for (int c = 0; c < ChannelCount; ++c)
        for (int y = 0; y < res[1]; ++y)
            for (int x = 0; x < res[0]; ++x) {
                const float u = float(hash_coords(77 + uint32_t(c), x, y, 0) >> 8) / float(1 << 24);
                s.at(c, x, y) = (c == MinHeight || c == MaxHeight) ? -2000.0f + 14000.0f * u : u;
            }
    if (res[0] > 1 && res[1] > 1) s.at(MaxHeight, 1, 1) = std::numeric_limits<float>::quiet_NaN(); // (1, 1) exists
    return s;
}
float in_layer_ref(double h, double lo, double hi) {
    if (std::isnan(h)) return 0.0f;
    return float(std::min(1.0, std::max(0.0, (h - lo) / (hi - lo))));
}
} // namespace

TEST(Exporters, UnityCloudMapChannels) {
    const Field2D s = random_set({{13, 9}}, {{{0, 0}}, {{1300, 900}}});
    const Field2D m = unity_cloud_map(s, {500, 8500}, nullptr);
    ASSERT_EQ(m.channels(), 4);
    ASSERT_EQ(m.resolution(), s.resolution());
    for (int y = 0; y < 9; ++y)
        for (int x = 0; x < 13; ++x) {
            ASSERT_EQ(m.at(0, x, y), s.at(Coverage, x, y));
            ASSERT_EQ(m.at(1, x, y), s.at(Precipitation, x, y));
            ASSERT_EQ(m.at(2, x, y), s.at(Type, x, y));
            ASSERT_FLOAT_EQ(m.at(3, x, y), in_layer_ref(s.at(MaxHeight, x, y), 500, 8500));
        }
    EXPECT_EQ(m.at(3, 1, 1), 0.0f); // NaN height -> 0
    EXPECT_THROW(unity_cloud_map(s, {100, 100}, nullptr), Error);
    EXPECT_THROW(unity_cloud_map(m, {0, 1}, nullptr), Error); // not an NDF set
}

TEST(Exporters, UnrealWeatherMapChannels) {
    const Field2D s = random_set({{11, 7}}, {{{-50, -50}}, {{50, 20}}});
    const Field2D m = unreal_weather_map(s, {0, 10000}, nullptr);
    for (int y = 0; y < 7; ++y)
        for (int x = 0; x < 11; ++x) {
            ASSERT_EQ(m.at(0, x, y), s.at(Coverage, x, y));
            ASSERT_EQ(m.at(1, x, y), s.at(Type, x, y));
            ASSERT_FLOAT_EQ(m.at(2, x, y), in_layer_ref(s.at(MinHeight, x, y), 0, 10000));
            ASSERT_FLOAT_EQ(m.at(3, x, y), in_layer_ref(s.at(MaxHeight, x, y), 0, 10000));
        }
    EXPECT_THROW(unreal_weather_map(s, {0, std::numeric_limits<double>::infinity()}, nullptr), Error);
}

namespace {
// Independent reference for the ambient channel: a midpoint sum of the density.
double ambient_midpoint(const VerticalProfile& p, double ao, double t, double f) {
    const int n = 200000;
    double above = 0, total = 0;
    for (int k = 0; k < n; ++k) {
        const double s = (k + 0.5) / n;
        const double d = p.density(t, s);
        total += d;
        if (s >= f) above += d;
    }
    return total > 0 ? 1.0 - ao * above / total : 1.0;
}
} // namespace

TEST(Exporters, UnityCloudLutMatchesTheAnalyticProfile) {
    const VerticalProfile p;
    UnityCloudLutOptions o; // 64 x 128
    const Field2D lut = unity_cloud_lut(p, o, nullptr);
    ASSERT_EQ(lut.width(), 64);
    ASSERT_EQ(lut.height(), 128);
    // Texel centres (cell-centred UV, as HDRP samples): R, G exact to float rounding.
    for (int j = 0; j < 128; ++j)
        for (int i = 0; i < 64; ++i) {
            const double t = (i + 0.5) / 64, f = (j + 0.5) / 128;
            const double d = p.density(t, f);
            ASSERT_FLOAT_EQ(lut.at(0, i, j), float(d));
            ASSERT_FLOAT_EQ(lut.at(1, i, j), float(1.0 - o.erosion_core * d));
            ASSERT_GE(lut.at(1, i, j), float(1.0 - o.erosion_core) - 1e-7f);
            ASSERT_LE(lut.at(1, i, j), 1.0f);
            // Ambient rises with height (less mass above) and stays in [1 - ao, 1].
            if (j) {
                ASSERT_GE(lut.at(2, i, j), lut.at(2, i, j - 1) - 1e-6f);
            }
            ASSERT_GE(lut.at(2, i, j), float(1.0 - o.ao_strength) - 1e-6f);
            ASSERT_LE(lut.at(2, i, j), 1.0f);
        }
    // B against an independent midpoint-sum reference, and the library's analytic form.
    for (int i : {0, 10, 21, 33, 50, 63})
        for (int j : {0, 5, 17, 40, 64, 100, 127}) {
            const double t = (i + 0.5) / 64, f = (j + 0.5) / 128;
            EXPECT_NEAR(lut.at(2, i, j), ambient_midpoint(p, o.ao_strength, t, f), 2e-5) << i << " " << j;
            EXPECT_NEAR(lut.at(2, i, j), unity_lut_ambient(p, o.ao_strength, t, f), 2e-6) << i << " " << j;
        }
    // The stated error (docs/ndf.md): below 0.035 at 64 x 128 under HDRP's bilinear lookup,
    // and smaller at a finer LUT.
    const double e = unity_cloud_lut_max_error(lut, p, o, 4);
    EXPECT_GT(e, 0.0);
    EXPECT_LT(e, 0.035);
    UnityCloudLutOptions fine = o;
    fine.types = 128;
    fine.heights = 256;
    EXPECT_LT(unity_cloud_lut_max_error(unity_cloud_lut(p, fine, nullptr), p, fine, 4), 0.75 * e);
    // Bad options name the parameter.
    UnityCloudLutOptions bad = o;
    bad.ao_strength = 1.5;
    try {
        unity_cloud_lut(p, bad, nullptr);
        ADD_FAILURE() << "no error";
    } catch (const Error& err) {
        EXPECT_NE(std::string(err.what()).find("ao_strength"), std::string::npos);
    }
    bad = o;
    bad.heights = 1;
    EXPECT_THROW(unity_cloud_lut(p, bad, nullptr), Error);
    EXPECT_THROW(parse_profile_gradients("0 0.1 0.2 0.3; 0 0.1 0.2"), Error);
    EXPECT_THROW(parse_profile_gradients("0 0.5 0.2 0.3; 0 0.1 0.2 0.3; 0 0.1 0.2 0.3; 0 0.1 0.2 0.3"), Error); // out of order
}

TEST(Exporters, UnityCloudLayerProjectionAndHemisphere) {
    // Coverage = 1 - r / R around the eye (radial gradient), type 1 (all cumulus):
    // every column of a row sees the same opacity 1 - (h / tan theta) / R.
    const Box2d box{{{-40000, -40000}}, {{40000, 40000}}};
    const Vec2i res{{512, 512}};
    Field2D set = make_ndf_set(res, box, 1000, 5000, nullptr);
    const double R = 30000;
    const Field2D radial = gradient_radial(res, box, {{0, 0}}, R, nullptr);
    std::copy(radial.channel(0).begin(), radial.channel(0).end(), set.channel(Coverage).begin());
    std::fill(set.channel(Type).begin(), set.channel(Type).end(), 1.0f);
    Field2D cirrus({{8, 8}}, 2, box, {"a", "b"});
    std::fill(cirrus.channel(1).begin(), cirrus.channel(1).end(), 0.7f);
    UnityCloudLayerOptions o;
    o.resolution = {{64, 32}};
    o.altitude = 2000;
    const Field2D full = unity_cloud_layer(set, &cirrus, 1, nullptr, 0, o, nullptr);
    EXPECT_DOUBLE_EQ(full.bounds().min[1], -90.0);
    for (int y = 0; y < 32; ++y) {
        const double theta = -0.5 * std::numbers::pi + std::numbers::pi * (y + 0.5) / 32;
        const double d = 2000 / std::tan(theta);
        for (int x = 0; x < 64; ++x) {
            if (y < 16) { // the lower half is 0 in every channel
                for (int c = 0; c < 4; ++c) ASSERT_EQ(full.at(c, x, y), 0.0f) << x << " " << y;
                continue;
            }
            ASSERT_NEAR(full.at(0, x, y), std::max(0.0, 1.0 - d / R), 2e-3) << x << " " << y;
            ASSERT_EQ(full.at(1, x, y), 0.0f); // type 1: no stratus
            const bool inside = std::abs(d * std::cos(2 * std::numbers::pi * (x + 0.5) / 64)) <= 40000 &&
                                std::abs(d * std::sin(2 * std::numbers::pi * (x + 0.5) / 64)) <= 40000;
            ASSERT_EQ(full.at(2, x, y), inside ? 0.7f : 0.0f) << x << " " << y; // cirrus channel 1, nothing beyond the map
            ASSERT_EQ(full.at(3, x, y), 0.0f);                              // no wispy map
        }
    }
    // Upper hemisphere only: the same sky in twice the rows' density of elevation.
    UnityCloudLayerOptions up = o;
    up.upper_hemisphere_only = true;
    up.resolution = {{64, 16}};
    const Field2D upper = unity_cloud_layer(set, &cirrus, 1, nullptr, 0, up, nullptr);
    EXPECT_DOUBLE_EQ(upper.bounds().min[1], 0.0);
    for (int y = 0; y < 16; ++y)
        for (int x = 0; x < 64; ++x)
            for (int c = 0; c < 4; ++c) ASSERT_NEAR(upper.at(c, x, y), full.at(c, x, y + 16), 1e-5) << c << " " << x << " " << y;
    // Stratus: type 0 puts all coverage in G; a tileable map covers the whole sky with cirrus.
    std::fill(set.channel(Type).begin(), set.channel(Type).end(), 0.0f);
    up.tileable = true;
    const Field2D strat = unity_cloud_layer(set, &cirrus, 1, nullptr, 0, up, nullptr);
    for (int y = 0; y < 16; ++y)
        for (int x = 0; x < 64; ++x) {
            ASSERT_EQ(strat.at(0, x, y), 0.0f);
            ASSERT_EQ(strat.at(2, x, y), 0.7f);
        }
    // Errors name the parameter.
    UnityCloudLayerOptions bad = o;
    bad.altitude = 0;
    EXPECT_THROW(unity_cloud_layer(set, nullptr, 0, nullptr, 0, bad, nullptr), Error);
    try {
        unity_cloud_layer(set, &cirrus, 2, nullptr, 0, o, nullptr);
        ADD_FAILURE() << "no error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("cirrus_channel"), std::string::npos);
    }
}

TEST(NdfGraphs, HzdWeatherWritesEveryEngineLayout) {
    const std::filesystem::path dir = std::filesystem::path(ATLAS_SOURCE_DIR) / "graphs";
    Session s(builtin_nodes());
    s.load_text(read_file_bytes(dir / "hzd_weather.yaml"), "hzd_weather.yaml", dir);
    CookOptions co;
    co.write_outputs = false;
    const auto get = [&](const char* node) { return std::get<Field2DPtr>(s.get(node, "out", co)); };
    const Field2DPtr w = get("weather");
    EXPECT_TRUE(*get("unity_map") == unity_cloud_map(*w, {0, 8000}, nullptr));
    EXPECT_TRUE(*get("unreal_map") == unreal_weather_map(*w, {0, 8000}, nullptr));
    const Field2DPtr lut = get("unity_lut");
    EXPECT_EQ(lut->channel_names(), (std::vector<std::string>{"density", "erosion", "ambient"}));
    const Field2DPtr sky = get("unity_sky");
    EXPECT_EQ(sky->channels(), 4);
    EXPECT_DOUBLE_EQ(sky->bounds().min[1], 0.0); // upper hemisphere
    // B and A come from the cirrus node's 'cirrus' and 'cirrostratus' channels: the zenith texel sees the eye's spot.
    const Field2DPtr cirrus = get("cirrus");
    float bmax = 0, amax = 0;
    for (size_t i = 0; i < sky->voxel_count(); ++i) {
        bmax = std::max(bmax, sky->channel(2)[i]);
        amax = std::max(amax, sky->channel(3)[i]);
    }
    EXPECT_GT(bmax, 0.0f);
    EXPECT_GT(amax, 0.0f);
    const int top = sky->height() - 1;
    const double theta = 0.5 * std::numbers::pi * (top + 0.5) / sky->height(), phi = 2 * std::numbers::pi * 0.5 / sky->width();
    const Vec2d p{{30000 + 3000 / std::tan(theta) * std::cos(phi), 30000 + 3000 / std::tan(theta) * std::sin(phi)}};
    EXPECT_FLOAT_EQ(sky->at(2, 0, top), cirrus->sample_world(cirrus->find_channel("cirrus"), p, WrapMode::Wrap));
    EXPECT_FLOAT_EQ(sky->at(3, 0, top), cirrus->sample_world(cirrus->find_channel("cirrostratus"), p, WrapMode::Wrap));
    // The file names say which engine each layout is for.
    const std::string yaml = read_file_bytes(dir / "hzd_weather.yaml");
    for (const char* f : {"hzd_weather_map_rgb_coverage_precip_type.png", "unity_hdrp_cloud_map_rgba_coverage_rain_type_maxheight.png",
                          "unity_hdrp_cloud_lut_rgb_density_erosion_ambient.png", "unreal_cloud_profile_lut_rgb_bottom_top_density.png",
                          "unity_hdrp_cloud_layer_latlong_rgba_cumulus_stratus_cirrus_wispy.png",
                          "unreal_cloud_weather_rgba_coverage_type_minheight_maxheight.png"})
        EXPECT_NE(yaml.find(f), std::string::npos) << f;
}

namespace {
// PNG chunk types in file order (the signature skipped); empty on a non-PNG.
std::vector<std::string> png_chunks(const std::string& d, int& bit_depth, int& colour_type) {
    std::vector<std::string> out;
    if (d.size() < 8 || d.compare(1, 3, "PNG") != 0) return out;
    for (size_t i = 8; i + 8 <= d.size();) {
        const uint32_t n = (uint32_t(uint8_t(d[i])) << 24) | (uint32_t(uint8_t(d[i + 1])) << 16) | (uint32_t(uint8_t(d[i + 2])) << 8) |
                           uint32_t(uint8_t(d[i + 3]));
        const std::string type = d.substr(i + 4, 4);
        if (type == "IHDR") {
            bit_depth = uint8_t(d[i + 16]);
            colour_type = uint8_t(d[i + 17]);
        }
        out.push_back(type);
        i += 12 + n;
    }
    return out;
}
} // namespace

TEST(NdfGraphs, EngineTexturesAreLinearPngs) {
    namespace fs = std::filesystem;
    const fs::path dir = fs::path(ATLAS_SOURCE_DIR) / "graphs";
    const fs::path out = fs::temp_directory_path() / ("atlas_engine_png_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()));
    fs::remove_all(out);
    fs::create_directories(out);
    Session s(builtin_nodes());
    s.load_text(read_file_bytes(dir / "hzd_weather.yaml"), "hzd_weather.yaml", dir);
    CookOptions co;
    co.out_dir = out;
    const std::string map = "unity_hdrp_cloud_map_rgba_coverage_rain_type_maxheight.png";
    const std::string lut = "unity_hdrp_cloud_lut_rgb_density_erosion_ambient.png";
    co.outputs = {map, lut};
    s.cook(co);
    for (const auto& [file, depth, colour] : {std::tuple{map, 8, 6}, std::tuple{lut, 16, 2}}) {
        int bits = 0, type = -1;
        const auto chunks = png_chunks(read_file_bytes(out / file), bits, type);
        ASSERT_FALSE(chunks.empty()) << file;
        EXPECT_EQ(bits, depth) << file;
        EXPECT_EQ(type, colour) << file; // 6 = RGBA, 2 = RGB
        for (const char* c : {"sRGB", "gAMA", "iCCP", "cHRM"}) // no colour-space tag: linear data
            EXPECT_EQ(std::find(chunks.begin(), chunks.end(), c), chunks.end()) << file << " has " << c;
    }
    fs::remove_all(out);
}

TEST(Exporters, ExtremeInputsStayFiniteAndInRange) {
    auto all_in_unit = [](const Field2D& f) {
        for (int c = 0; c < f.channels(); ++c)
            for (float v : f.channel(c))
                if (!(v >= 0.0f && v <= 1.0f)) return false;
        return true;
    };
    // 1 m and 1000 km maps, NaN and infinite values in the set.
    for (double extent : {1.0, 1e6}) {
        const Box2d box{{{-extent, -extent}}, {{extent, extent}}};
        Field2D s = random_set({{9, 7}}, box);
        s.at(Coverage, 2, 2) = std::numeric_limits<float>::quiet_NaN();
        s.at(Type, 3, 3) = std::numeric_limits<float>::infinity();
        s.at(MinHeight, 4, 4) = -std::numeric_limits<float>::infinity();
        const Field2D u = unreal_weather_map(s, {0, 1e4}, nullptr);
        for (int c : {2, 3})
            for (float v : u.channel(c)) ASSERT_TRUE(v >= 0.0f && v <= 1.0f);
        for (double altitude : {1e-3, 1.0, 1e9})
            for (bool tile : {false, true}) {
                UnityCloudLayerOptions o;
                o.resolution = {{32, 16}};
                o.altitude = altitude;
                o.eye = {{1e12, -1e12}}; // far outside the map
                o.tileable = tile;
                const Field2D clean = random_set({{9, 7}}, box); // channels in [0, 1] (its one NaN is a height)
                ASSERT_TRUE(all_in_unit(unity_cloud_layer(clean, &clean, 0, &clean, 7, o, nullptr)));
                const Field2D sky = unity_cloud_layer(s, &s, 0, &s, 7, o, nullptr); // NaN coverage: NaN may spread, never Inf
                for (int c = 0; c < 4; ++c)
                    for (float v : sky.channel(c)) ASSERT_FALSE(std::isinf(v)) << c;
            }
    }
    // A 1 x 1 set seen from its centre.
    const Field2D one = random_set({{1, 1}}, {{{0, 0}}, {{1, 1}}});
    UnityCloudLayerOptions o1;
    o1.resolution = {{1, 1}};
    o1.eye = {{0.5, 0.5}};
    EXPECT_NO_THROW(unity_cloud_layer(one, nullptr, 0, nullptr, 0, o1, nullptr));
    // A profile with no density anywhere: density 0, erosion 1, ambient 1 (nothing above occludes).
    VerticalProfile empty;
    for (auto& g : empty.types) g = {1, 1, 1, 1};
    UnityCloudLutOptions small;
    small.types = 2;
    small.heights = 2;
    const Field2D lut = unity_cloud_lut(empty, small, nullptr);
    EXPECT_TRUE(all_in_unit(lut));
    for (int j = 0; j < 2; ++j)
        for (int i = 0; i < 2; ++i) {
            EXPECT_EQ(lut.at(0, i, j), 0.0f);
            EXPECT_EQ(lut.at(1, i, j), 1.0f);
            EXPECT_EQ(lut.at(2, i, j), 1.0f);
        }
    UnityCloudLutOptions tall;
    tall.types = 4;
    tall.heights = 8192;
    const Field2D big = unity_cloud_lut(VerticalProfile{}, tall, nullptr);
    EXPECT_TRUE(all_in_unit(big));
}

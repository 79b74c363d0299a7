// FC6 weather presets: parsing, positioned errors, ranges, blending.
#include "atlas/ndf/weather_preset.h"

#include "atlas/core/error.h"
#include "ndf/weather_files.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

using namespace atlas;
using namespace atlas::ndf;

namespace {
const char* kPresets = R"(atlas_presets: 1
presets:
  clear:
    cumulus_coverage: 0.1
    wind_speed: 2
  storm:
    cumulus_coverage: 0.9
    rain_intensity: 1
    lightning: 0.7
    wind_direction: 350
    wind_speed: 10
    min_height: 800
    max_height: 9000
)";

// The ParseError a text raises (fails the test when it raises none).
ParseError parse_error(const std::string& text) {
    try {
        parse_presets(text, "p.yaml");
    } catch (const ParseError& e) {
        return e;
    }
    ADD_FAILURE() << "no ParseError for:\n" << text;
    return ParseError({"", 0, 0}, "");
}
} // namespace

TEST(WeatherPreset, ParsesFieldsAndDefaults) {
    const auto p = parse_presets(kPresets, "p.yaml");
    ASSERT_EQ(p.size(), 2u);
    EXPECT_EQ(p[0].name, "clear");
    EXPECT_EQ(p[0].cumulus_coverage, 0.1);
    EXPECT_EQ(p[0].wind_speed, 2);
    const WeatherPreset def;
    EXPECT_EQ(p[0].cirrus_coverage, def.cirrus_coverage); // left out: default
    EXPECT_EQ(p[0].max_height, def.max_height);
    EXPECT_EQ(p[1].name, "storm");
    EXPECT_EQ(p[1].lightning, 0.7);
    EXPECT_EQ(p[1].max_height, 9000);
    EXPECT_EQ(find_preset(p, "storm"), 1);
    EXPECT_THROW(find_preset(p, "drizzle"), Error);
}

TEST(WeatherPreset, ErrorsNameFileLineAndField) {
    // Out of range: the value's line and the field.
    ParseError e = parse_error("atlas_presets: 1\npresets:\n  a:\n    fog: 0.2\n    rain_intensity: 1.5\n");
    EXPECT_EQ(e.where().file, "p.yaml");
    EXPECT_EQ(e.where().line, 5);
    EXPECT_NE(std::string(e.what()).find("p.yaml:5:"), std::string::npos) << e.what();
    EXPECT_NE(e.detail().find("rain_intensity"), std::string::npos) << e.what();
    EXPECT_NE(e.detail().find("[0, 1]"), std::string::npos) << e.what();
    // Unknown field with a suggestion.
    e = parse_error("atlas_presets: 1\npresets:\n  a:\n    cumulus_coverge: 0.2\n");
    EXPECT_EQ(e.where().line, 4);
    EXPECT_NE(e.detail().find("did you mean 'cumulus_coverage'"), std::string::npos) << e.what();
    // Not a number.
    e = parse_error("atlas_presets: 1\npresets:\n  a:\n    wind_speed: fast\n");
    EXPECT_EQ(e.where().line, 4);
    EXPECT_NE(e.detail().find("wind_speed must be a number"), std::string::npos) << e.what();
    // NaN and Inf are out of range.
    EXPECT_EQ(parse_error("atlas_presets: 1\npresets:\n  a: {fog: .nan}\n").where().line, 3);
    EXPECT_NE(parse_error("atlas_presets: 1\npresets:\n  a: {wind_speed: .inf}\n").detail().find("wind_speed"), std::string::npos);
    // Direction is [0, 360): 360 is out.
    EXPECT_NE(parse_error("atlas_presets: 1\npresets:\n  a: {wind_direction: 360}\n").detail().find("[0, 360)"), std::string::npos);
    // min above max, duplicates, version, empty, bad YAML.
    e = parse_error("atlas_presets: 1\npresets:\n  a: {min_height: 5000, max_height: 4000}\n");
    EXPECT_EQ(e.where().line, 3);
    EXPECT_NE(e.detail().find("min_height"), std::string::npos);
    EXPECT_NE(parse_error("atlas_presets: 1\npresets:\n  a: {fog: 0}\n  a: {fog: 1}\n").detail().find("duplicate"), std::string::npos);
    EXPECT_NE(parse_error("atlas_presets: 2\npresets:\n  a: {fog: 0}\n").detail().find("atlas_presets: 1"), std::string::npos);
    EXPECT_NE(parse_error("atlas_presets: 1\npresets: {}\n").detail().find("non-empty"), std::string::npos);
    EXPECT_EQ(parse_error("atlas_presets: 1\npresets:\n  a: {fog: [0\n").where().file, "p.yaml");
    EXPECT_NE(parse_error("atlas_presets: 1\npresets:\n  a: {fog: 0}\ncolour: red\n").detail().find("unknown key 'colour'"),
              std::string::npos);
}

TEST(WeatherPreset, ValidateNamesTheField) {
    WeatherPreset p;
    p.name = "x";
    EXPECT_NO_THROW(validate_preset(p));
    p.cirrus_coverage = NAN;
    try {
        validate_preset(p);
        FAIL();
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("preset 'x': cirrus_coverage"), std::string::npos) << e.what();
    }
}

TEST(WeatherPreset, LerpEndsExactMiddleLinearWindAsVector) {
    const auto p = parse_presets(kPresets, "p.yaml");
    const WeatherPreset a = lerp_presets(p[0], p[1], 0), b = lerp_presets(p[0], p[1], 1);
    for (const auto& f : preset_fields()) {
        EXPECT_EQ(a.*f.member, p[0].*f.member) << f.name;
        EXPECT_EQ(b.*f.member, p[1].*f.member) << f.name;
    }
    EXPECT_EQ(a.name, "clear");
    EXPECT_EQ(b.name, "storm");
    const WeatherPreset m = lerp_presets(p[0], p[1], 0.25);
    EXPECT_DOUBLE_EQ(m.cumulus_coverage, 0.1 + 0.25 * 0.8);
    EXPECT_DOUBLE_EQ(m.max_height, 4000 + 0.25 * 5000);
    // Wind: the velocity vector is lerped.
    const Vec2d v = wind_velocity(p[0]) * 0.75 + wind_velocity(p[1]) * 0.25;
    const Vec2d w = wind_velocity(m);
    EXPECT_NEAR(w[0], v[0], 1e-9);
    EXPECT_NEAR(w[1], v[1], 1e-9);
    // 350 deg and 10 deg meet at 0 deg, not at 180 deg.
    WeatherPreset x = p[1], y = p[1];
    x.wind_direction = 350;
    y.wind_direction = 10;
    const WeatherPreset xy = lerp_presets(x, y, 0.5);
    EXPECT_TRUE(xy.wind_direction < 1e-9 || xy.wind_direction > 360 - 1e-9) << xy.wind_direction;
    // Opposite winds cancel to speed 0 and the result stays valid.
    y.wind_direction = 170;
    const WeatherPreset zero = lerp_presets(x, y, 0.5);
    EXPECT_NEAR(zero.wind_speed, 0, 1e-9);
    EXPECT_NO_THROW(validate_preset(zero));
    // t outside [0, 1] clamps, NaN gives a.
    EXPECT_EQ(lerp_presets(p[0], p[1], 7).cumulus_coverage, p[1].cumulus_coverage);
    EXPECT_EQ(lerp_presets(p[0], p[1], NAN).cumulus_coverage, p[0].cumulus_coverage);
}

TEST(WeatherPreset, ProductionPresetsParse) {
    const auto p = ndf_nodes::read_presets_file(std::filesystem::path(ATLAS_SOURCE_DIR) / "graphs" / "fc6" / "presets.yaml");
    EXPECT_GE(p.size(), 6u);
    for (const auto& x : p) EXPECT_NO_THROW(validate_preset(x)) << x.name;
    const WeatherPreset& broken = p[size_t(find_preset(p, "broken_clouds"))];
    EXPECT_EQ(broken.cumulus_coverage, 0.54); // the values the talk shows
    EXPECT_EQ(broken.cirrus_coverage, 0.45);
    EXPECT_EQ(broken.horizon_coverage, 0.95);
    EXPECT_THROW(ndf_nodes::read_presets_file("/nonexistent/presets.yaml"), Error);
}

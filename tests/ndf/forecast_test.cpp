// FC6 forecast: parsing errors, keys, looping, continuity, drift, regions, the sequence and manifest.
#include "atlas/ndf/forecast.h"

#include "atlas/core/error.h"
#include "atlas/core/field_math.h"
#include "atlas/graph/evaluator.h"
#include "atlas/graph/node.h"
#include "atlas/ndf/ndf_set.h"
#include "ndf/weather_files.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <tbb/global_control.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>

using namespace atlas;
using namespace atlas::ndf;

namespace {
const std::filesystem::path kGraphs = std::filesystem::path(ATLAS_SOURCE_DIR) / "graphs";

std::vector<WeatherPreset> test_presets() {
    return parse_presets(R"(atlas_presets: 1
presets:
  calm: {cumulus_coverage: 0.3, wind_speed: 0}
  breezy: {cumulus_coverage: 0.5, wind_direction: 45, wind_speed: 6}
  storm: {cumulus_coverage: 0.9, rain_intensity: 1, lightning: 0.5, wind_direction: 120, wind_speed: 14}
)",
                         "presets.yaml");
}

const char* kForecast = R"(atlas_forecast: 1
presets: presets.yaml
period_hours: 120
transition_hours: 4
regions:
  - name: all
    keys: [[0, calm], [10, breezy], [50, storm], [80, breezy]]
  - name: east
    rect: [6000, 0, 12000, 12000]
    blend: 2000
    keys: [[6, storm], [30, calm]]
)";

Forecast test_forecast() { return parse_forecast(kForecast, "forecast.yaml", test_presets()); }

WeatherMapSpec small_spec() {
    WeatherMapSpec s;
    s.resolution = {{64, 64}};
    s.bounds = Box2d{{{0, 0}}, {{12000, 12000}}};
    s.period = {{4, 4}};
    s.octaves = 3;
    s.seed = 3;
    return s;
}

ParseError forecast_error(const std::string& text) {
    try {
        parse_forecast(text, "f.yaml", test_presets());
    } catch (const ParseError& e) {
        return e;
    }
    ADD_FAILURE() << "no ParseError for:\n" << text;
    return ParseError({"", 0, 0}, "");
}

double max_abs_diff(const Field2D& a, const Field2D& b) {
    double m = 0;
    for (int c = 0; c < a.channels(); ++c)
        for (size_t i = 0; i < a.voxel_count(); ++i) m = std::max(m, double(std::abs(a.channel(c)[i] - b.channel(c)[i])));
    return m;
}

// Shortest distance between two drifts on the torus of the map.
double torus_distance(Vec2d a, Vec2d b, Vec2d size) {
    double d2 = 0;
    for (int k = 0; k < 2; ++k) {
        double d = std::fmod(std::abs(a[k] - b[k]), size[k]);
        d = std::min(d, size[k] - d);
        d2 += d * d;
    }
    return std::sqrt(d2);
}
} // namespace

TEST(Forecast, ErrorsNameFileLineAndField) {
    const std::string head = "atlas_forecast: 1\npresets: p.yaml\nregions:\n  - name: r\n    keys:\n";
    // A key out of order: its line, both hours.
    ParseError e = forecast_error(head + "      - [0, calm]\n      - [12, breezy]\n      - [6, storm]\n");
    EXPECT_EQ(e.where().line, 8);
    EXPECT_NE(e.detail().find("key hour 6 is not after the previous key (12)"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("f.yaml:8:"), std::string::npos) << e.what();
    // Equal hours are out of order too.
    EXPECT_EQ(forecast_error(head + "      - [3, calm]\n      - [3, breezy]\n").where().line, 7);
    // Beyond the period, negative.
    EXPECT_NE(forecast_error(head + "      - [120, calm]\n").detail().find("out of range [0, 120)"), std::string::npos);
    EXPECT_NE(forecast_error(head + "      - [-1, calm]\n").detail().find("out of range"), std::string::npos);
    // Unknown preset: names the known ones.
    e = forecast_error(head + "      - [0, drizzle]\n");
    EXPECT_EQ(e.where().line, 6);
    EXPECT_NE(e.detail().find("unknown preset 'drizzle'"), std::string::npos) << e.what();
    EXPECT_NE(e.detail().find("calm"), std::string::npos);
    // Regions after the first need a rect; the first takes none.
    e = forecast_error(head + "      - [0, calm]\n  - name: s\n    keys: [[0, calm]]\n");
    EXPECT_NE(e.detail().find("region 's': regions after the first need a rect"), std::string::npos) << e.what();
    EXPECT_NE(forecast_error("atlas_forecast: 1\nregions:\n  - name: r\n    rect: [0, 0, 1, 1]\n    keys: [[0, calm]]\n")
                  .detail()
                  .find("whole map"),
              std::string::npos);
    EXPECT_NE(forecast_error(
                  "atlas_forecast: 1\nregions:\n  - {name: r, keys: [[0, calm]]}\n  - {name: s, rect: [5, 0, 1, 1], keys: [[0, calm]]}\n")
                  .detail()
                  .find("xmin < xmax"),
              std::string::npos);
    // Period, transition, version, keys.
    EXPECT_NE(forecast_error("atlas_forecast: 1\nperiod_hours: 0\nregions: []\n").detail().find("period_hours"), std::string::npos);
    EXPECT_NE(forecast_error("atlas_forecast: 1\ntransition_hours: -2\nregions: []\n").detail().find("transition_hours"),
              std::string::npos);
    EXPECT_NE(forecast_error("atlas_forecast: 3\nregions: []\n").detail().find("atlas_forecast: 1"), std::string::npos);
    EXPECT_NE(forecast_error(head + "      - [0]\n").detail().find("[hour, preset]"), std::string::npos);
    EXPECT_NE(forecast_error("atlas_forecast: 1\nregion: []\n").detail().find("unknown key 'region'"), std::string::npos);
}

TEST(Forecast, KeyedHourReproducesItsPresetExactly) {
    const Forecast f = test_forecast();
    for (size_t r = 0; r < f.regions.size(); ++r)
        for (const auto& k : f.regions[r].keys) {
            const WeatherPreset p = forecast_preset(f, int(r), k.hour);
            const WeatherPreset& want = f.presets[size_t(k.preset)];
            EXPECT_EQ(p.name, want.name);
            for (const auto& fi : preset_fields()) EXPECT_EQ(p.*fi.member, want.*fi.member) << fi.name << " at hour " << k.hour;
            // And the same hour one loop later or earlier.
            EXPECT_EQ(forecast_preset(f, int(r), k.hour + 120).cumulus_coverage, want.cumulus_coverage);
            EXPECT_EQ(forecast_preset(f, int(r), k.hour - 240).cumulus_coverage, want.cumulus_coverage);
        }
    // The production forecast too.
    const Forecast g = ndf_nodes::read_forecast_file(kGraphs / "fc6" / "forecast.yaml");
    for (size_t r = 0; r < g.regions.size(); ++r)
        for (const auto& k : g.regions[r].keys)
            for (const auto& fi : preset_fields())
                EXPECT_EQ(forecast_preset(g, int(r), k.hour).*fi.member, g.presets[size_t(k.preset)].*fi.member) << fi.name;
}

TEST(Forecast, TransitionIsSmoothstepOverTheLastHoursBeforeAKey) {
    const Forecast f = test_forecast();
    // Key at 10 (breezy) after calm at 0, transition 4 h: calm until 6, then smoothstep.
    EXPECT_EQ(forecast_blend(f, 0, 5.9).weight, 0);
    for (double h : {6.5, 8.0, 9.5}) {
        const PresetBlend b = forecast_blend(f, 0, h);
        EXPECT_EQ(b.from, 0);
        EXPECT_EQ(b.to, 1);
        const double u = (h - 6) / 4;
        EXPECT_NEAR(b.weight, u * u * (3 - 2 * u), 1e-12);
    }
    // The last key wraps to the first: breezy at 80 -> calm at 120 == 0.
    const PresetBlend w = forecast_blend(f, 0, 118);
    EXPECT_EQ(w.from, 1);
    EXPECT_EQ(w.to, 0);
    EXPECT_NEAR(w.weight, 0.5, 1e-12);
    // Before the first key of a region (east starts at 6): the wrap segment from its last key (30).
    const PresetBlend e = forecast_blend(f, 1, 4);
    EXPECT_EQ(f.presets[size_t(e.from)].name, "calm");
    EXPECT_EQ(f.presets[size_t(e.to)].name, "storm");
    EXPECT_NEAR(e.weight, 0.5, 1e-12); // 4 h = the middle of the ramp [2, 6]
    // transition 0: the whole gap.
    Forecast g = f;
    g.transition_hours = 0;
    EXPECT_NEAR(forecast_blend(g, 0, 5).weight, 0.5, 1e-12);
}

TEST(Forecast, FieldsTransitionOverTheirOwnHours) {
    // 002: a storm is preceded by darkening clouds: coverage ramps over 8 h, rain over the
    // last hour, the wind over 2 h, every other field over transition_hours (4 h).
    std::string text = kForecast;
    text.replace(text.find("regions:"), 0, "field_transition_hours: {cumulus_coverage: 8, rain_intensity: 1, wind: 2}\n");
    const Forecast f = parse_forecast(text, "forecast.yaml", test_presets());
    ASSERT_EQ(f.field_transition_hours.size(), 3u);
    const auto smooth = [](double u) { return u <= 0 ? 0.0 : u >= 1 ? 1.0 : u * u * (3 - 2 * u); };
    const WeatherPreset& breezy = f.presets[1];
    const WeatherPreset& storm = f.presets[2];
    // Breezy (key 10) -> storm (key 50), two hours before the storm.
    const double h = 48;
    EXPECT_NEAR(forecast_blend(f, 0, h).weight, smooth(0.5), 1e-12);
    EXPECT_NEAR(forecast_field_weight(f, 0, h, "cumulus_coverage"), smooth((h - 42) / 8), 1e-12);
    EXPECT_EQ(forecast_field_weight(f, 0, h, "rain_intensity"), 0.0);
    EXPECT_NEAR(forecast_field_weight(f, 0, h, "fog"), smooth(0.5), 1e-12); // no override: transition_hours
    const WeatherPreset p = forecast_preset(f, 0, h);
    EXPECT_NEAR(p.cumulus_coverage, breezy.cumulus_coverage + (storm.cumulus_coverage - breezy.cumulus_coverage) * smooth(0.75), 1e-12);
    EXPECT_EQ(p.rain_intensity, breezy.rain_intensity); // the rain has not started
    EXPECT_NEAR(p.lightning, storm.lightning * smooth(0.5), 1e-12);
    EXPECT_EQ(p.wind_speed, breezy.wind_speed); // the wind turns in the last 2 h
    EXPECT_EQ(forecast_preset(f, 0, 49.5).rain_intensity, smooth(0.5) * storm.rain_intensity);
    // A keyed hour still gives its preset exactly, every field.
    const WeatherPreset k = forecast_preset(f, 0, 50);
    for (const auto& fi : preset_fields()) EXPECT_EQ(k.*fi.member, storm.*fi.member) << fi.name;
    // The drift integrates the wind at its own transition (midpoint rule, as above).
    const Vec2d size{{12000, 12000}};
    const int n = 120000;
    const double dt = 120.0 / n;
    Vec2d total{}, at{};
    for (int i = 0; i < n; ++i) {
        total = total + wind_velocity(forecast_preset(f, 0, (i + 0.5) * dt)) * (dt * 3600);
        if (std::abs((i + 1) * dt - 55.55) < 0.5 * dt) at = total;
    }
    Vec2d ref;
    for (int a = 0; a < 2; ++a) ref[a] = at[a] - 55.55 / 120 * (total[a] - std::round(total[a] / size[a]) * size[a]);
    EXPECT_LT(torus_distance(forecast_drift(f, 0, 55.55, size), ref, size), 1.0);
    // Both manifests carry every field's transition length and the overridden fields' weights.
    const auto j = nlohmann::json::parse(forecast_manifest_json(f, small_spec(), 48, 1, 2));
    EXPECT_EQ(j["field_transition_hours"]["cumulus_coverage"], 8.0);
    EXPECT_EQ(j["field_transition_hours"]["rain_intensity"], 1.0);
    EXPECT_EQ(j["field_transition_hours"]["wind"], 2.0);
    EXPECT_EQ(j["field_transition_hours"]["heights"], 4.0);
    EXPECT_EQ(j["field_transition_hours"].size(), transition_fields().size());
    EXPECT_NEAR(j["frames"][0]["regions"][0]["field_weights"]["cumulus_coverage"].get<double>(), smooth(0.75), 1e-12);
    EXPECT_EQ(j["frames"][0]["regions"][0]["values"]["rain_intensity"], 0.0);
    const Field2D t = forecast_manifest_table(f, small_spec(), 48, 1, 2);
    EXPECT_EQ(t.at(t.find_channel("transition:rain_intensity"), 0, 0), 1.0f);
    EXPECT_EQ(t.at(t.find_channel("transition:fog"), 1, 1), 4.0f);
    EXPECT_NEAR(t.at(t.find_channel("weight:cumulus_coverage"), 0, 0), smooth(0.75), 1e-6);
    EXPECT_EQ(t.at(t.find_channel("weight:rain_intensity"), 0, 0), 0.0f);
    // Bad names and lengths, at their lines.
    const std::string head = "atlas_forecast: 1\npresets: p.yaml\n";
    const std::string tail = "regions:\n  - {name: r, keys: [[0, calm]]}\n";
    ParseError e = forecast_error(head + "field_transition_hours:\n  wind_speed: 2\n" + tail);
    EXPECT_EQ(e.where().line, 4);
    EXPECT_NE(e.detail().find("'wind_speed' is not a transition field"), std::string::npos) << e.what();
    EXPECT_NE(e.detail().find("wind"), std::string::npos);
    EXPECT_NE(forecast_error(head + "field_transition_hours: {fog: -1}\n" + tail).detail().find("fog = -1 must be >= 0"), std::string::npos);
    EXPECT_NE(forecast_error(head + "field_transition_hours: 3\n" + tail).detail().find("must be a map"), std::string::npos);
    Forecast bad = f;
    bad.field_transition_hours["heights"] = std::nan("");
    EXPECT_THROW(validate_forecast(bad), Error);
}

TEST(Forecast, DriftIntegratesTheWindAndLoops) {
    const Forecast f = test_forecast();
    const Vec2d size{{12000, 12000}};
    for (int r = 0; r < 2; ++r) {
        // Independent reference: the midpoint rule over the blended presets' wind.
        const double h0 = f.regions[size_t(r)].keys.front().hour;
        const int n = 120000;
        const double dt = 120.0 / n;
        Vec2d total{}, at[3]{};
        const double probes[3] = {h0 + 7.3, h0 + 55.55, h0 + 101};
        for (int i = 0; i < n; ++i) {
            const double t = h0 + (i + 0.5) * dt;
            total = total + wind_velocity(forecast_preset(f, r, t)) * (dt * 3600);
            for (int k = 0; k < 3; ++k)
                if (std::abs(h0 + (i + 1) * dt - probes[k]) < 0.5 * dt) at[k] = total;
        }
        for (int k = 0; k < 3; ++k) {
            Vec2d ref;
            for (int a = 0; a < 2; ++a) {
                const double excess = total[a] - std::round(total[a] / size[a]) * size[a];
                ref[a] = at[k][a] - (probes[k] - h0) / 120 * excess;
            }
            EXPECT_LT(torus_distance(forecast_drift(f, r, probes[k], size), ref, size), 1.0) << "region " << r << " hour " << probes[k];
        }
        // The loop: hour 120 is hour 0, approached continuously.
        EXPECT_EQ(forecast_drift(f, r, 0, size), forecast_drift(f, r, 120, size));
        EXPECT_LT(torus_distance(forecast_drift(f, r, 120 - 1e-6, size), forecast_drift(f, r, 0, size), size), 0.1);
        EXPECT_LT(torus_distance(forecast_drift(f, r, h0, size), Vec2d{}, size), 1e-6);
    }
}

TEST(Forecast, MapsLoopAndChangeContinuously) {
    const Forecast f = test_forecast();
    const WeatherMapSpec spec = small_spec();
    const Field2D noise = make_weather_noise(spec, nullptr);
    for (double t : {0.0, 7.5, 49.0, 100.25}) {
        const Field2D a = forecast_weather_map(f, noise, t, nullptr);
        EXPECT_TRUE(a == forecast_weather_map(f, noise, t + 120, nullptr)) << t; // t and t + 120 h: identical bytes
        EXPECT_TRUE(a == forecast_weather_map(f, noise, t - 360, nullptr)) << t;
    }
    // Across the loop point, and inside transitions (where presets and
    // winds change fastest): a small dt changes the map by a small amount,
    // shrinking in proportion to dt (Lipschitz: bilinear noise, smoothstep).
    // Scale: 14 m/s moves the noise 50 m (0.27 texel) in 0.001 h.
    for (double t : {119.9999, 8.0, 48.0, 4.0}) {
        const Field2D a = forecast_weather_map(f, noise, t, nullptr);
        const double d1 = max_abs_diff(a, forecast_weather_map(f, noise, t + 1e-4, nullptr));
        const double d2 = max_abs_diff(a, forecast_weather_map(f, noise, t + 2.5e-5, nullptr));
        EXPECT_LT(d1, 0.02) << t;
        EXPECT_LE(d2, 0.3 * d1 + 1e-5) << t;
    }
    // A 3-hour step does change the map (the test can fail).
    EXPECT_GT(max_abs_diff(forecast_weather_map(f, noise, 8, nullptr), forecast_weather_map(f, noise, 11, nullptr)), 0.1);
}

TEST(Forecast, RegionsBlendAtTheirBorders) {
    const Forecast f = test_forecast();
    const WeatherMapSpec spec = small_spec();
    const Field2D noise = make_weather_noise(spec, nullptr);
    const double hour = 20;
    const Field2D m = forecast_weather_map(f, noise, hour, nullptr);
    const Field2D all = preset_weather_map(forecast_preset(f, 0, hour), noise, forecast_drift(f, 0, hour, spec.bounds.size()), nullptr);
    const Field2D east = preset_weather_map(forecast_preset(f, 1, hour), noise, forecast_drift(f, 1, hour, spec.bounds.size()), nullptr);
    int inside = 0, outside = 0, border = 0;
    for (int y = 0; y < 64; ++y)
        for (int x = 0; x < 64; ++x) {
            const double px = m.texel_center(x, y)[0], py = m.texel_center(x, y)[1];
            // Region 'east': x in [6000, 12000] with a 2000 m border centred on the edges.
            const double inner = std::min({px - 6000, 12000 - px, py, 12000 - py});
            for (int c = 0; c < 4; ++c) {
                if (px < 5000) {
                    EXPECT_NEAR(m.at(c, x, y), all.at(c, x, y), 1e-6);
                    ++outside;
                } else if (inner > 1000) {
                    EXPECT_NEAR(m.at(c, x, y), east.at(c, x, y), 1e-6);
                    ++inside;
                } else {
                    const float lo = std::min(all.at(c, x, y), east.at(c, x, y)), hi = std::max(all.at(c, x, y), east.at(c, x, y));
                    EXPECT_GE(m.at(c, x, y), lo - 1e-6f);
                    EXPECT_LE(m.at(c, x, y), hi + 1e-6f);
                    ++border;
                }
            }
        }
    EXPECT_GT(inside, 100);
    EXPECT_GT(outside, 100);
    EXPECT_GT(border, 100);
}

TEST(Forecast, PresetMapFormulas) {
    const WeatherMapSpec spec = small_spec();
    const Field2D noise = make_weather_noise(spec, nullptr);
    WeatherPreset p;
    p.name = "p";
    p.cumulus_coverage = 0;
    EXPECT_EQ(channel_stats(preset_weather_map(p, noise, {}, nullptr).channel(0)).max, 0.0); // no cumulus: no coverage
    p.cumulus_coverage = 1;
    p.rain_intensity = 0.6;
    p.lightning = 1;
    const Field2D full = preset_weather_map(p, noise, {}, nullptr);
    for (size_t i = 0; i < full.voxel_count(); ++i) {
        ASSERT_EQ(full.channel(0)[i], 1.0f);
        ASSERT_NEAR(full.channel(1)[i], 0.6, 1e-6); // rain * smoothstep(thr, 1, 1)
        const double base = std::clamp(p.cloud_type + p.type_variation * (2 * noise.channel(1)[i] - 1), 0.0, 1.0);
        ASSERT_NEAR(full.channel(2)[i], base + (1 - base) * 0.6, 1e-6);
        ASSERT_EQ(full.channel(3)[i], float(p.cirrus_coverage));
    }
    // The noise is equalised, so cumulus_coverage is the share of the sky:
    // coverage > c exactly where n > 1 - c.
    for (double c : {0.2, 0.54, 0.85}) {
        p.cumulus_coverage = c;
        const Field2D m = preset_weather_map(p, noise, {}, nullptr);
        size_t above = 0;
        for (float v : m.channel(0)) above += v > c + 1e-6;
        EXPECT_NEAR(double(above) / double(m.voxel_count()), c, 2.0 / double(m.voxel_count()) + 0.01) << c;
    }
    // A whole map size of drift is no drift (the noise tiles).
    p.cumulus_coverage = 0.5;
    EXPECT_LT(max_abs_diff(preset_weather_map(p, noise, {}, nullptr), preset_weather_map(p, noise, spec.bounds.size(), nullptr)), 1e-5);
    EXPECT_THROW(preset_weather_map(p, noise, Vec2d{{NAN, 0}}, nullptr), Error);
}

TEST(Forecast, ExtremeInputs) {
    const WeatherMapSpec spec = small_spec();
    const Field2D noise = make_weather_noise(spec, nullptr);
    auto presets = test_presets();
    // Zero wind and one key: a static map at every hour.
    Forecast still;
    still.presets = presets;
    still.regions.push_back({"all", true, {}, 0, {{0, 0}}});
    const Field2D s0 = forecast_weather_map(still, noise, 0, nullptr);
    EXPECT_TRUE(s0 == forecast_weather_map(still, noise, 77.7, nullptr));
    EXPECT_EQ(forecast_drift(still, 0, 50, spec.bounds.size()), Vec2d{});
    // Huge wind (500 m/s, 1800 km/h) over tiny and huge maps: finite, looping.
    presets[2].wind_speed = 500;
    Forecast fast;
    fast.presets = presets;
    fast.regions.push_back({"all", true, {}, 0, {{0, 2}, {60, 0}}});
    for (double size : {1.0, 1e7}) {
        const Vec2d sz{{size, size}};
        for (double h : {0.0, 33.3, 119.99}) {
            const Vec2d d = forecast_drift(fast, 0, h, sz);
            EXPECT_TRUE(std::isfinite(d[0]) && std::isfinite(d[1]));
            EXPECT_GE(d[0], 0);
            EXPECT_LT(d[0], size);
        }
        EXPECT_LT(torus_distance(forecast_drift(fast, 0, 120 - 1e-9, sz), forecast_drift(fast, 0, 0, sz), sz), 1e-3 * size + 1e-3);
    }
    const Field2D m = forecast_weather_map(fast, noise, 33.3, nullptr);
    for (int c = 0; c < 4; ++c)
        for (float v : m.channel(c)) ASSERT_TRUE(std::isfinite(v) && v >= 0 && v <= 1);
    // Beyond the wind range: a clear error.
    presets[2].wind_speed = 1e9;
    fast.presets = presets;
    try {
        validate_forecast(fast);
        FAIL();
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("wind_speed"), std::string::npos) << e.what();
    }
    // A 1-hour forecast: period 1 h, two keys half an hour apart.
    Forecast hour = test_forecast();
    hour.period_hours = 1;
    hour.transition_hours = 0;
    hour.regions.resize(1);
    hour.regions[0].keys = {{0, 0}, {0.5, 2}};
    EXPECT_NO_THROW(validate_forecast(hour));
    EXPECT_TRUE(forecast_weather_map(hour, noise, 0.3, nullptr) == forecast_weather_map(hour, noise, 5.3, nullptr));
    EXPECT_EQ(forecast_preset(hour, 0, 0.5).cumulus_coverage, presets[2].cumulus_coverage);
    // Out-of-order keys built in code: a clear error too.
    hour.regions[0].keys = {{0.5, 0}, {0.25, 2}};
    EXPECT_THROW(validate_forecast(hour), Error);
    EXPECT_THROW(forecast_weather_map(hour, noise, 0, nullptr), Error);
    // 1 m and 1e9 m maps, 1 x 1 texels: finite values in range.
    for (double size : {1.0, 1e9})
        for (Vec2i res : {Vec2i{{1, 1}}, Vec2i{{17, 5}}}) {
            WeatherMapSpec w = spec;
            w.bounds = Box2d{{{-size, 0}}, {{0, size}}};
            w.resolution = res;
            const Field3D seq = cook_forecast(test_forecast(), w, 5, 13, 3, nullptr, nullptr);
            for (int c = 0; c < 4; ++c)
                for (float v : seq.channel(c)) ASSERT_TRUE(std::isfinite(v) && v >= 0 && v <= 1) << size;
        }
    // Non-finite hours, bad sequences.
    EXPECT_THROW(forecast_blend(test_forecast(), 0, NAN), Error);
    EXPECT_THROW(cook_forecast(test_forecast(), spec, 0, 0, 4, nullptr, nullptr), Error);
    EXPECT_THROW(cook_forecast(test_forecast(), spec, 0, 1, 0, nullptr, nullptr), Error);
}

TEST(Forecast, SequenceSlicesManifestAndThreads) {
    const Forecast f = test_forecast();
    const WeatherMapSpec spec = small_spec();
    const Field3D seq = cook_forecast(f, spec, 2, 7.5, 6, nullptr, nullptr);
    ASSERT_EQ(seq.nz(), 6);
    EXPECT_EQ(seq.channel_names(), weather_map_channels());
    const Field2D noise = make_weather_noise(spec, nullptr);
    for (int z = 0; z < 6; ++z) {
        const Field2D m = forecast_weather_map(f, noise, 2 + 7.5 * z, nullptr);
        for (int c = 0; c < 4; ++c)
            for (int y = 0; y < 64; y += 9)
                for (int x = 0; x < 64; x += 7) ASSERT_EQ(seq.at(c, x, y, z), m.at(c, x, y)) << z;
    }
    {
        tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
        EXPECT_TRUE(seq == cook_forecast(f, spec, 2, 7.5, 6, nullptr, nullptr)); // same bytes on 1 thread
    }
    const auto j = nlohmann::json::parse(forecast_manifest_json(f, spec, 2, 7.5, 6));
    EXPECT_EQ(j["slices"], 6);
    ASSERT_EQ(j["frames"].size(), 6u);
    EXPECT_EQ(j["frames"][1]["hour"], 9.5);
    EXPECT_EQ(j["regions"][1]["name"], "east");
    for (const auto& fr : j["frames"])
        for (const auto& r : fr["regions"]) {
            double wsum = 0;
            for (const auto& p : r["presets"]) wsum += p["weight"].get<double>();
            EXPECT_NEAR(wsum, 1, 1e-12);
            EXPECT_TRUE(r["values"].contains("cumulus_coverage"));
        }
    const Field2D t = forecast_manifest_table(f, spec, 2, 7.5, 6);
    EXPECT_EQ(t.width(), 6);
    EXPECT_EQ(t.height(), 2);
    EXPECT_EQ(t.at(t.find_channel("hour"), 1, 0), 9.5f);
    EXPECT_NEAR(t.at(t.find_channel("weight"), 1, 0), j["frames"][1]["regions"][0]["presets"][1]["weight"].get<double>(), 1e-6);
    for (int i = 0; i < 6; ++i)
        for (int r = 0; r < 2; ++r) {
            double sum = 0;
            for (const auto& p : f.presets) sum += t.at(t.find_channel("preset:" + p.name), i, r);
            EXPECT_NEAR(sum, 1, 1e-6);
            const PresetBlend b = forecast_blend(f, r, 2 + 7.5 * i);
            EXPECT_NEAR(t.at(t.find_channel("preset:" + f.presets[size_t(b.to)].name), i, r), b.from == b.to ? 1 : b.weight, 1e-6);
        }
}

TEST(Forecast, Fc6GraphCooks) {
    Session s(builtin_nodes());
    const std::string text = [] {
        std::ifstream in(kGraphs / "fc6_forecast.yaml");
        return std::string(std::istreambuf_iterator<char>(in), {});
    }();
    s.load_text(text, "fc6_forecast.yaml", kGraphs);
    CookOptions co;
    co.write_outputs = false;
    const auto maps = std::get<Field3DPtr>(s.get("forecast", "maps", co));
    EXPECT_EQ(maps->nz(), 40);
    EXPECT_EQ(maps->channels(), 4);
    const auto table = std::get<Field2DPtr>(s.get("forecast", "manifest", co));
    EXPECT_EQ(table->width(), 40);
    EXPECT_EQ(table->height(), 3);
    EXPECT_EQ(std::get<Field2DPtr>(s.get("cirrus", "out", co))->channels(), 3);
    EXPECT_EQ(std::get<Field2DPtr>(s.get("cirrus_horizon", "out", co))->resolution(), (Vec2i{{2048, 128}}));
    // The cirrus tile over the map feeds the Unity cloud layer: cirrus (B) and wispy (A) only.
    const auto layer = std::get<Field2DPtr>(s.get("unity_cirrus_layer", "out", co));
    ASSERT_EQ(layer->channels(), 4);
    EXPECT_EQ(channel_stats(layer->channel(0)).max, 0.0);
    EXPECT_EQ(channel_stats(layer->channel(1)).max, 0.0);
    EXPECT_GT(channel_stats(layer->channel(2)).max, 0.5);
    EXPECT_GT(channel_stats(layer->channel(3)).mean, 0.1);
}

TEST(Forecast, NodesHashTheirFilesAndReportErrors) {
    namespace fs = std::filesystem;
    const fs::path dir =
        fs::temp_directory_path() / ("atlas_fc6_nodes_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()));
    fs::create_directories(dir);
    auto write = [&](const std::string& name, const std::string& text) { std::ofstream(dir / name) << text; };
    write("p.yaml", "atlas_presets: 1\npresets:\n  a: {cumulus_coverage: 0.3, wind_speed: 4}\n  b: {cumulus_coverage: 0.8}\n");
    write("f.yaml", "atlas_forecast: 1\npresets: p.yaml\nregions:\n  - name: all\n    keys: [[0, a], [60, b]]\n");
    Session s(builtin_nodes());
    s.load_text(R"(atlas: 1
nodes:
  fc:
    type: ndf/forecast
    params: {forecast: f.yaml, resolution: [16, 16], bounds_max: [1000, 1000], slices: 4, step_hours: 30}
  pr:
    type: ndf/weather_preset
    params: {presets: p.yaml, preset: a, resolution: [16, 16], bounds_max: [1000, 1000]}
outputs: []
)",
                "g.yaml", dir);
    CookOptions co;
    co.write_outputs = false;
    const auto h0 = s.node_hashes();
    const auto maps0 = std::get<Field3DPtr>(s.get("fc", "maps", co));
    const auto pr0 = std::get<Field2DPtr>(s.get("pr", "out", co));
    // Editing the presets file (which the forecast names) changes both nodes' hashes and results.
    write("p.yaml", "atlas_presets: 1\npresets:\n  a: {cumulus_coverage: 0.6, wind_speed: 4}\n  b: {cumulus_coverage: 0.8}\n");
    const auto h1 = s.node_hashes();
    EXPECT_NE(h0.at("fc"), h1.at("fc"));
    EXPECT_NE(h0.at("pr"), h1.at("pr"));
    EXPECT_FALSE(*maps0 == *std::get<Field3DPtr>(s.get("fc", "maps", co)));
    EXPECT_FALSE(*pr0 == *std::get<Field2DPtr>(s.get("pr", "out", co)));
    // Errors reach the caller with the file position and the field.
    write("f.yaml", "atlas_forecast: 1\npresets: p.yaml\nregions:\n  - name: all\n    keys: [[0, a], [60, c]]\n");
    try {
        s.get("fc", "maps", co);
        ADD_FAILURE() << "no error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("f.yaml:5:"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("unknown preset 'c'"), std::string::npos) << e.what();
    }
    s.set_text("pr", "preset", "zzz");
    EXPECT_THROW(s.get("pr", "out", co), Error);
    fs::remove_all(dir);
}

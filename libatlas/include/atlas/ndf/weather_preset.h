// atlas/ndf/weather_preset.h - Far Cry 6 style weather presets (GDC 2022).
//
// A preset is a named set of weather values: the FC6 weather-manager fields
// (cumulus, cirrus and horizon coverage, rain intensity, wind, lightning,
// fog) plus the NDF-graph parameters they drive (cloud type, its spatial
// variation, coverage contrast, rain threshold, cloud base and top). Presets
// live in a YAML file (docs/ndf.md, "Weather presets"):
//
//   atlas_presets: 1
//   presets:
//     broken_clouds: {cumulus_coverage: 0.54, cirrus_coverage: 0.45, wind_speed: 6}
//
// Fields left out take the defaults below. Pure functions, thread-safe,
// deterministic. Errors are atlas::ParseError ("file:line:col: error: ...")
// naming the preset and the field.
#pragma once

#include "atlas/core/math.h"

#include <string>
#include <vector>

namespace atlas::ndf {

struct WeatherPreset {
    std::string name;
    // --- the FC6 weather fields ---
    double cumulus_coverage = 0.5; // [0,1] share of the sky with cumulus-layer clouds
    double cirrus_coverage = 0.3;  // [0,1] opacity of the cirrus layer
    double horizon_coverage = 0.5; // [0,1] opacity of the cirrus horizon strip
    double rain_intensity = 0;     // [0,1]
    double wind_direction = 0;     // degrees [0,360): direction the wind blows TOWARD, counter-clockwise from +x
    double wind_speed = 5;         // m/s [0, 500]
    double lightning = 0;          // [0,1] lightning frequency
    double fog = 0;                // [0,1] fog density
    // --- NDF graph parameters the preset drives ---
    double cloud_type = 0.5;      // [0,1] mean cloud type (0 stratus .. 2/3 cumulus, 1 cumulonimbus)
    double type_variation = 0.3;  // [0,1] spread of type around cloud_type, driven by a noise
    double coverage_contrast = 3; // [0.1,100] slope of the noise -> coverage map around its midpoint
    double rain_threshold = 0.5;  // [0,1) coverage where rain starts; precipitation = rain * smoothstep(thr, 1, coverage)
    double min_height = 1500;     // metres [-1000, 30000]: cloud base
    double max_height = 4000;     // metres [-1000, 30000], >= min_height: cloud top
};

// One numeric preset field: its YAML name, range, unit and meaning (what
// the parser checks and docs list). `member` points into WeatherPreset.
struct PresetFieldInfo {
    const char* name;
    double WeatherPreset::*member;
    double lo, hi;
    bool hi_open; // the range is [lo, hi) instead of [lo, hi]
    const char* unit;
    const char* doc;
};
const std::vector<PresetFieldInfo>& preset_fields();

// Throws atlas::Error "preset 'NAME': FIELD = V is out of range [lo, hi]"
// (also for NaN/Inf, and for min_height > max_height).
void validate_preset(const WeatherPreset& p);

// Parses a presets file's text; `filename` is used in error positions.
// Errors: bad YAML, a missing or wrong 'atlas_presets: 1' line, no
// presets, duplicate names, unknown fields (with "did you mean"), values
// that are not numbers or out of range, min_height > max_height.
std::vector<WeatherPreset> parse_presets(const std::string& text, const std::string& filename);

// Index of the preset named `name`; throws atlas::Error listing the names.
int find_preset(const std::vector<WeatherPreset>& presets, const std::string& name);

// Blend of two presets, t in [0,1] (clamped). Every field is lerped, except
// the wind: its velocity vector is lerped (no spin through the long way
// round), so direction and speed come from the blended vector. t = 0 returns
// `a` and t = 1 returns `b` exactly (fields and name); other t give the
// name "a>b".
WeatherPreset lerp_presets(const WeatherPreset& a, const WeatherPreset& b, double t);

// Wind velocity (m/s) of a preset: speed * (cos dir, sin dir).
Vec2d wind_velocity(const WeatherPreset& p);

} // namespace atlas::ndf

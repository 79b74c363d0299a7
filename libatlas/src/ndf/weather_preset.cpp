// Weather presets: YAML parsing with positioned errors, validation, blending.
#include "atlas/ndf/weather_preset.h"

#include "atlas/core/error.h"
#include "atlas/core/option_schema.h"
#include "atlas/io/yaml_document.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <set>

namespace atlas::ndf {

const std::vector<PresetFieldInfo>& preset_fields() {
    using P = WeatherPreset;
    static const std::vector<PresetFieldInfo> fields = {
        {"cumulus_coverage", &P::cumulus_coverage, 0, 1, false, "", "share of the sky with cumulus-layer clouds"},
        {"cirrus_coverage", &P::cirrus_coverage, 0, 1, false, "", "opacity of the cirrus layer"},
        {"horizon_coverage", &P::horizon_coverage, 0, 1, false, "", "opacity of the cirrus horizon strip"},
        {"rain_intensity", &P::rain_intensity, 0, 1, false, "", "rain intensity"},
        {"wind_direction", &P::wind_direction, 0, 360, true, "deg", "direction the wind blows toward, counter-clockwise from +x"},
        {"wind_speed", &P::wind_speed, 0, 500, false, "m/s", "wind speed: the weather map scrolls with it"},
        {"lightning", &P::lightning, 0, 1, false, "", "lightning frequency"},
        {"fog", &P::fog, 0, 1, false, "", "fog density"},
        {"cloud_type", &P::cloud_type, 0, 1, false, "", "mean cloud type (0 stratus, 1/3 stratocumulus, 2/3 cumulus, 1 cumulonimbus)"},
        {"type_variation", &P::type_variation, 0, 1, false, "",
         "spread of the type around cloud_type (type = cloud_type + variation (2 n - 1))"},
        {"coverage_contrast", &P::coverage_contrast, 0.1, 100, false, "", "slope of the noise -> coverage map"},
        {"rain_threshold", &P::rain_threshold, 0, 1, true, "", "coverage where rain starts"},
        {"min_height", &P::min_height, -1000, 30000, false, "m", "cloud base"},
        {"max_height", &P::max_height, -1000, 30000, false, "m", "cloud top (>= min_height)"},
    };
    return fields;
}

namespace {

// Range check of one field; empty when fine, else the reason.
std::string check_field(const PresetFieldInfo& f, double v) {
    const bool ok = std::isfinite(v) && v >= f.lo && (f.hi_open ? v < f.hi : v <= f.hi);
    if (ok) return {};
    return std::string(f.name) + " = " + detail::number_text(v) + " is out of range [" + detail::number_text(f.lo) + ", " + detail::number_text(f.hi) + (f.hi_open ? ")" : "]");
}

size_t edit_distance(const std::string& a, const std::string& b) {
    std::vector<size_t> row(b.size() + 1);
    for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
    for (size_t i = 1; i <= a.size(); ++i) {
        size_t diag = row[0];
        row[0] = i;
        for (size_t j = 1; j <= b.size(); ++j) {
            const size_t up = row[j];
            row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] == b[j - 1] ? 0 : 1)});
            diag = up;
        }
    }
    return row[b.size()];
}

} // namespace

void validate_preset(const WeatherPreset& p) {
    for (const auto& f : preset_fields()) {
        const std::string why = check_field(f, p.*f.member);
        if (!why.empty()) throw Error("preset '" + p.name + "': " + why);
    }
    if (p.min_height > p.max_height)
        throw Error("preset '" + p.name + "': min_height = " + detail::number_text(p.min_height) + " is above max_height = " + detail::number_text(p.max_height));
}

std::vector<WeatherPreset> parse_presets(const std::string& text, const std::string& filename) {
    const YAML::Node root = io::load_yaml(text, filename);
    io::require_versioned_map(root, filename, "atlas_presets", "1", "expected a map with 'atlas_presets: 1' and 'presets'",
                              "expected 'atlas_presets: 1' (the presets file version)");
    io::reject_unknown_keys(root, filename, {"atlas_presets", "presets"}, "'atlas_presets' and 'presets'");
    const YAML::Node list = root["presets"];
    if (!list || !list.IsMap() || list.size() == 0)
        throw ParseError(list ? io::yaml_location(filename, list) : SourceLocation{filename, 1, 1},
                         "'presets' must be a non-empty map of name -> fields");

    std::vector<WeatherPreset> out;
    std::set<std::string> names;
    for (const auto& entry : list) {
        WeatherPreset p;
        p.name = entry.first.Scalar();
        if (p.name.empty()) throw ParseError(io::yaml_location(filename, entry.first), "a preset needs a name");
        if (!names.insert(p.name).second) throw ParseError(io::yaml_location(filename, entry.first), "duplicate preset '" + p.name + "'");
        const YAML::Node& body = entry.second;
        if (!body.IsMap()) throw ParseError(io::yaml_location(filename, body), "preset '" + p.name + "': expected a map of field: value");
        for (const auto& kv : body) {
            const std::string field = kv.first.Scalar();
            const auto& fields = preset_fields();
            auto it = std::find_if(fields.begin(), fields.end(), [&](const PresetFieldInfo& f) { return field == f.name; });
            if (it == fields.end()) {
                std::string best;
                size_t best_d = 4;
                for (const auto& f : fields)
                    if (size_t d = edit_distance(field, f.name); d < best_d) best_d = d, best = f.name;
                throw ParseError(io::yaml_location(filename, kv.first), "preset '" + p.name + "': unknown field '" + field + "'" +
                                                                (best.empty() ? "" : " (did you mean '" + best + "'?)"));
            }
            double v = 0;
            try {
                if (!kv.second.IsScalar()) throw YAML::Exception(kv.second.Mark(), "not a scalar");
                v = kv.second.as<double>();
            } catch (const YAML::Exception&) {
                throw ParseError(io::yaml_location(filename, kv.second), "preset '" + p.name + "': " + field + " must be a number");
            }
            if (const std::string why = check_field(*it, v); !why.empty())
                throw ParseError(io::yaml_location(filename, kv.second), "preset '" + p.name + "': " + why);
            p.*(it->member) = v;
        }
        if (p.min_height > p.max_height)
            throw ParseError(io::yaml_location(filename, entry.first),
                             "preset '" + p.name + "': min_height = " + detail::number_text(p.min_height) + " is above max_height = " + detail::number_text(p.max_height));
        out.push_back(std::move(p));
    }
    return out;
}

int find_preset(const std::vector<WeatherPreset>& presets, const std::string& name) {
    for (size_t i = 0; i < presets.size(); ++i)
        if (presets[i].name == name) return int(i);
    std::string known;
    for (const auto& p : presets) known += (known.empty() ? "" : ", ") + p.name;
    throw Error("unknown preset '" + name + "' (presets: " + known + ")");
}

Vec2d wind_velocity(const WeatherPreset& p) {
    const double a = p.wind_direction * std::numbers::pi / 180.0;
    return Vec2d{{std::cos(a), std::sin(a)}} * p.wind_speed;
}

WeatherPreset lerp_presets(const WeatherPreset& a, const WeatherPreset& b, double t) {
    t = std::isfinite(t) ? std::clamp(t, 0.0, 1.0) : 0.0;
    if (t == 0) return a;
    if (t == 1) return b;
    WeatherPreset r;
    r.name = a.name + ">" + b.name;
    for (const auto& f : preset_fields()) r.*f.member = a.*f.member + (b.*f.member - a.*f.member) * t;
    const Vec2d w = wind_velocity(a) * (1 - t) + wind_velocity(b) * t;
    r.wind_speed = std::hypot(w[0], w[1]);
    if (r.wind_speed > 0) {
        double deg = std::atan2(w[1], w[0]) * 180.0 / std::numbers::pi;
        if (deg < 0) deg += 360;
        r.wind_direction = deg >= 360 ? 0 : deg;
    } else {
        r.wind_direction = a.wind_direction; // opposite winds cancel: keep a direction, speed 0
    }
    return r;
}

} // namespace atlas::ndf

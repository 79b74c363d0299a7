// Forecast: parsing, time blending, wind drift, and the cook into a map sequence.
#include "atlas/ndf/forecast.h"

#include "atlas/core/error.h"
#include "atlas/core/option_schema.h"
#include "atlas/ndf/generators.h"
#include "atlas/ndf/ndf_set.h"

#include <nlohmann/json.hpp>
#include "atlas/core/parallel.h"
#include "atlas/io/yaml_document.h"

#include <algorithm>
#include <cmath>

namespace atlas::ndf {

namespace {

double as_number(const std::string& file, const YAML::Node& n, const std::string& what) {
    try {
        if (n.IsScalar()) return n.as<double>();
    } catch (const YAML::Exception&) {
    }
    throw ParseError(io::yaml_location(file, n), what + " must be a number");
}

// The key segment containing `hour` (already in [0, period)), as the
// time-line tau in [h_0, h_0 + period): key i at h_i, next key at `end`.
struct Segment {
    size_t i = 0;
    double tau = 0, start = 0, end = 0, ramp = 0; // ramp: smoothstep length L ending at `end`
};

// The smoothstep length of a transition `length` (0: the whole gap) over a gap.
double ramp_of(double length, double gap) { return length > 0 ? std::min(length, gap) : gap; }

Segment find_segment(const Forecast& f, const ForecastRegion& r, double hour, double length) {
    const auto& k = r.keys;
    Segment s;
    s.tau = hour < k.front().hour ? hour + f.period_hours : hour;
    s.i = k.size() - 1;
    for (size_t j = 0; j + 1 < k.size(); ++j)
        if (s.tau < k[j + 1].hour) {
            s.i = j;
            break;
        }
    s.start = k[s.i].hour;
    s.end = s.i + 1 < k.size() ? k[s.i + 1].hour : k.front().hour + f.period_hours;
    s.ramp = ramp_of(length, s.end - s.start);
    return s;
}

double wrap_hour(const Forecast& f, double hour) {
    if (!std::isfinite(hour)) throw Error("forecast: hour " + detail::number_text(hour) + " is not finite");
    double h = std::fmod(hour, f.period_hours);
    if (h < 0) h += f.period_hours;
    return h >= f.period_hours ? 0.0 : h;
}

// Integral of smoothstep(end - L, end, t) dt from `start` to tau.
double smoothstep_integral(const Segment& s, double tau) {
    const double e0 = s.end - s.ramp;
    if (tau <= e0 || s.ramp <= 0) return std::max(0.0, tau - s.end);
    if (tau < s.end) {
        const double u = (tau - e0) / s.ramp;
        return s.ramp * (u * u * u - 0.5 * u * u * u * u);
    }
    return 0.5 * s.ramp + (tau - s.end);
}

// Drift (unwrapped, metres) from h_0 to tau along the region's keys (the wind's transitions).
Vec2d raw_drift(const Forecast& f, const ForecastRegion& r, double tau) {
    const double length = field_transition(f, "wind");
    Vec2d d{};
    const auto& k = r.keys;
    for (size_t i = 0; i < k.size(); ++i) {
        Segment s;
        s.i = i;
        s.start = k[i].hour;
        s.end = i + 1 < k.size() ? k[i + 1].hour : k.front().hour + f.period_hours;
        s.ramp = ramp_of(length, s.end - s.start);
        if (tau <= s.start) break;
        const double t = std::min(tau, s.end);
        const Vec2d va = wind_velocity(f.presets[size_t(k[i].preset)]);
        const Vec2d vb = wind_velocity(f.presets[size_t(k[(i + 1) % k.size()].preset)]);
        d = d + (va * (t - s.start) + (vb - va) * smoothstep_integral(s, t)) * 3600.0; // m/s * h -> m
    }
    return d;
}

double wrap_metres(double v, double size) {
    double w = std::fmod(v, size);
    if (w < 0) w += size;
    return w >= size ? 0.0 : w;
}
} // namespace

const std::vector<TransitionField>& transition_fields() {
    static const std::vector<TransitionField> names = [] {
        std::vector<TransitionField> v;
        for (const auto& fi : preset_fields()) {
            const std::string n = fi.name;
            if (n == "wind_direction" || n == "max_height") continue; // in their groups
            if (n == "wind_speed") v.push_back({"wind", {"wind_speed", "wind_direction"}});
            else if (n == "min_height") v.push_back({"heights", {"min_height", "max_height"}});
            else v.push_back({n, {n}});
        }
        return v;
    }();
    return names;
}

double field_transition(const Forecast& f, const std::string& name) {
    const auto it = f.field_transition_hours.find(name);
    return it != f.field_transition_hours.end() ? it->second : f.transition_hours;
}

namespace {
std::vector<std::string> transition_names() {
    std::vector<std::string> v;
    for (const auto& t : transition_fields()) v.push_back(t.name);
    return v;
}
std::string transition_name_error(const std::string& name) {
    std::string list;
    for (const auto& n : transition_names()) list += (list.empty() ? "" : ", ") + n;
    return "field_transition_hours: '" + name + "' is not a transition field (expected one of: " + list + ")";
}
} // namespace

void validate_forecast(const Forecast& f) {
    if (!(std::isfinite(f.period_hours) && f.period_hours > 0 && f.period_hours <= 10000))
        throw Error("forecast: period_hours = " + detail::number_text(f.period_hours) + " is out of range (0, 10000]");
    if (!(std::isfinite(f.transition_hours) && f.transition_hours >= 0))
        throw Error("forecast: transition_hours = " + detail::number_text(f.transition_hours) + " must be >= 0");
    for (const auto& [name, hours] : f.field_transition_hours) {
        const auto names = transition_names();
        if (std::find(names.begin(), names.end(), name) == names.end()) throw Error("forecast: " + transition_name_error(name));
        if (!(std::isfinite(hours) && hours >= 0))
            throw Error("forecast: field_transition_hours: " + name + " = " + detail::number_text(hours) + " must be >= 0");
    }
    if (f.presets.empty()) throw Error("forecast: no presets");
    for (const auto& p : f.presets) validate_preset(p);
    if (f.regions.empty()) throw Error("forecast: no regions (region 0 covers the whole map)");
    for (size_t r = 0; r < f.regions.size(); ++r) {
        const auto& reg = f.regions[r];
        const std::string who = "forecast: region '" + reg.name + "'";
        if (r == 0 && !reg.whole_map) throw Error(who + ": the first region covers the whole map and takes no rect");
        if (r > 0 && reg.whole_map) throw Error(who + ": regions after the first need a rect");
        if (!reg.whole_map && !reg.rect.valid()) throw Error(who + ": rect must have xmin < xmax and ymin < ymax");
        if (!(std::isfinite(reg.blend) && reg.blend >= 0)) throw Error(who + ": blend = " + detail::number_text(reg.blend) + " must be >= 0 metres");
        if (reg.keys.empty()) throw Error(who + ": no keys (expected [hour, preset] pairs)");
        for (size_t i = 0; i < reg.keys.size(); ++i) {
            const auto& k = reg.keys[i];
            if (!(std::isfinite(k.hour) && k.hour >= 0 && k.hour < f.period_hours))
                throw Error(who + ": key hour " + detail::number_text(k.hour) + " is out of range [0, " + detail::number_text(f.period_hours) + ")");
            if (i > 0 && !(k.hour > reg.keys[i - 1].hour))
                throw Error(who + ": key hour " + detail::number_text(k.hour) + " is not after the previous key (" + detail::number_text(reg.keys[i - 1].hour) + ")");
            if (k.preset < 0 || size_t(k.preset) >= f.presets.size()) throw Error(who + ": key preset index out of range");
        }
    }
}

Forecast parse_forecast(const std::string& text, const std::string& filename, std::vector<WeatherPreset> presets) {
    const YAML::Node root = io::load_yaml(text, filename);
    io::require_versioned_map(root, filename, "atlas_forecast", "1", "expected a map with 'atlas_forecast: 1', 'presets' and 'regions'",
                              "expected 'atlas_forecast: 1' (the forecast file version)");
    io::reject_unknown_keys(root, filename, {"atlas_forecast", "presets", "period_hours", "transition_hours", "field_transition_hours", "regions"},
                            "atlas_forecast, presets, period_hours, transition_hours, field_transition_hours, regions");
    Forecast f;
    f.presets = std::move(presets);
    if (f.presets.empty()) throw ParseError({filename, 1, 1}, "no presets to key the forecast with");
    if (const YAML::Node n = root["period_hours"]) {
        f.period_hours = as_number(filename, n, "period_hours");
        if (!(f.period_hours > 0 && f.period_hours <= 10000))
            throw ParseError(io::yaml_location(filename, n), "period_hours = " + detail::number_text(f.period_hours) + " is out of range (0, 10000]");
    }
    if (const YAML::Node n = root["transition_hours"]) {
        f.transition_hours = as_number(filename, n, "transition_hours");
        if (!(f.transition_hours >= 0 && std::isfinite(f.transition_hours)))
            throw ParseError(io::yaml_location(filename, n), "transition_hours = " + detail::number_text(f.transition_hours) + " must be >= 0");
    }
    if (const YAML::Node n = root["field_transition_hours"]) {
        if (!n.IsMap()) throw ParseError(io::yaml_location(filename, n), "field_transition_hours must be a map of field: hours");
        const auto names = transition_names();
        for (const auto& kv : n) {
            const std::string name = kv.first.Scalar();
            if (std::find(names.begin(), names.end(), name) == names.end())
                throw ParseError(io::yaml_location(filename, kv.first), transition_name_error(name));
            const double hours = as_number(filename, kv.second, "field_transition_hours: " + name);
            if (!(hours >= 0 && std::isfinite(hours)))
                throw ParseError(io::yaml_location(filename, kv.second), "field_transition_hours: " + name + " = " + detail::number_text(hours) + " must be >= 0");
            f.field_transition_hours[name] = hours;
        }
    }
    const YAML::Node regions = root["regions"];
    if (!regions || !regions.IsSequence() || regions.size() == 0)
        throw ParseError(regions ? io::yaml_location(filename, regions) : SourceLocation{filename, 1, 1}, "'regions' must be a non-empty list");
    for (size_t r = 0; r < regions.size(); ++r) {
        const YAML::Node& rn = regions[r];
        if (!rn.IsMap()) throw ParseError(io::yaml_location(filename, rn), "a region is a map with name, keys (and rect, blend)");
        ForecastRegion reg;
        reg.name = rn["name"] && rn["name"].IsScalar() ? rn["name"].Scalar() : "region" + std::to_string(r);
        const std::string who = "region '" + reg.name + "'";
        io::reject_unknown_keys(rn, filename, {"name", "rect", "blend", "keys"}, "name, rect, blend, keys", who + ": ");
        if (const YAML::Node n = rn["rect"]) {
            if (r == 0) throw ParseError(io::yaml_location(filename, n), who + ": the first region covers the whole map and takes no rect");
            if (!n.IsSequence() || n.size() != 4)
                throw ParseError(io::yaml_location(filename, n), who + ": rect must be [xmin, ymin, xmax, ymax] in metres");
            double v[4];
            for (size_t i = 0; i < 4; ++i) v[i] = as_number(filename, n[i], who + ": rect");
            reg.whole_map = false;
            reg.rect = Box2d{{{v[0], v[1]}}, {{v[2], v[3]}}};
            if (!reg.rect.valid() || !std::isfinite(v[0] + v[1] + v[2] + v[3]))
                throw ParseError(io::yaml_location(filename, n), who + ": rect must have xmin < xmax and ymin < ymax");
        } else if (r > 0) {
            throw ParseError(io::yaml_location(filename, rn), who + ": regions after the first need a rect [xmin, ymin, xmax, ymax]");
        }
        if (const YAML::Node n = rn["blend"]) {
            reg.blend = as_number(filename, n, who + ": blend");
            if (!(reg.blend >= 0 && std::isfinite(reg.blend))) throw ParseError(io::yaml_location(filename, n), who + ": blend must be >= 0 metres");
        }
        const YAML::Node keys = rn["keys"];
        if (!keys || !keys.IsSequence() || keys.size() == 0)
            throw ParseError(keys ? io::yaml_location(filename, keys) : io::yaml_location(filename, rn),
                             who + ": 'keys' must be a non-empty list of [hour, preset]");
        for (const auto& kn : keys) {
            YAML::Node hn, pn;
            if (kn.IsSequence() && kn.size() == 2) {
                hn = kn[0];
                pn = kn[1];
            } else if (kn.IsMap() && kn["hour"] && kn["preset"]) {
                hn = kn["hour"];
                pn = kn["preset"];
            } else {
                throw ParseError(io::yaml_location(filename, kn), who + ": a key is [hour, preset] or {hour: H, preset: NAME}");
            }
            ForecastKey k;
            k.hour = as_number(filename, hn, who + ": key hour");
            if (!(k.hour >= 0 && k.hour < f.period_hours))
                throw ParseError(io::yaml_location(filename, hn),
                                 who + ": key hour " + detail::number_text(k.hour) + " is out of range [0, " + detail::number_text(f.period_hours) + ")");
            if (!reg.keys.empty() && !(k.hour > reg.keys.back().hour))
                throw ParseError(io::yaml_location(filename, hn), who + ": key hour " + detail::number_text(k.hour) + " is not after the previous key (" +
                                                          detail::number_text(reg.keys.back().hour) + "); keys must be in increasing hour order");
            if (!pn.IsScalar()) throw ParseError(io::yaml_location(filename, pn), who + ": key preset must be a preset name");
            try {
                k.preset = find_preset(f.presets, pn.Scalar());
            } catch (const Error& e) {
                throw ParseError(io::yaml_location(filename, pn), who + ": " + e.what());
            }
            reg.keys.push_back(k);
        }
        f.regions.push_back(std::move(reg));
    }
    validate_forecast(f);
    return f;
}

std::string forecast_presets_entry(const std::string& text, const std::string& filename) {
    const YAML::Node root = io::load_yaml(text, filename);
    const YAML::Node n = root.IsMap() ? root["presets"] : YAML::Node();
    if (!n || !n.IsScalar() || n.Scalar().empty())
        throw ParseError(n ? io::yaml_location(filename, n) : SourceLocation{filename, 1, 1}, "'presets' must name the presets file");
    return n.Scalar();
}

PresetBlend forecast_blend(const Forecast& f, int region, double hour) {
    if (region < 0 || size_t(region) >= f.regions.size()) throw Error("forecast: region index " + std::to_string(region) + " out of range");
    const auto& r = f.regions[size_t(region)];
    const Segment s = find_segment(f, r, wrap_hour(f, hour), f.transition_hours);
    PresetBlend b;
    b.from = r.keys[s.i].preset;
    b.to = r.keys[(s.i + 1) % r.keys.size()].preset;
    b.weight = r.keys.size() == 1 ? 0.0 : smoothstep(s.end - s.ramp, s.end, s.tau);
    if (r.keys.size() == 1) b.to = b.from;
    return b;
}

double forecast_field_weight(const Forecast& f, int region, double hour, const std::string& name) {
    if (region < 0 || size_t(region) >= f.regions.size()) throw Error("forecast: region index " + std::to_string(region) + " out of range");
    const auto& r = f.regions[size_t(region)];
    if (r.keys.size() == 1) return 0.0;
    const Segment s = find_segment(f, r, wrap_hour(f, hour), field_transition(f, name));
    return smoothstep(s.end - s.ramp, s.end, s.tau);
}

WeatherPreset forecast_preset(const Forecast& f, int region, double hour) {
    const PresetBlend b = forecast_blend(f, region, hour);
    const WeatherPreset& from = f.presets[size_t(b.from)];
    const WeatherPreset& to = f.presets[size_t(b.to)];
    WeatherPreset p = lerp_presets(from, to, b.weight);
    for (const auto& t : transition_fields()) {
        if (!f.field_transition_hours.count(t.name)) continue;
        // The group's fields as lerp_presets blends them at the group's own weight.
        const WeatherPreset q = lerp_presets(from, to, forecast_field_weight(f, region, hour, t.name));
        for (const auto& fi : preset_fields())
            if (std::find(t.fields.begin(), t.fields.end(), fi.name) != t.fields.end()) p.*fi.member = q.*fi.member;
    }
    return p;
}

Vec2d forecast_drift(const Forecast& f, int region, double hour, Vec2d map_size) {
    if (region < 0 || size_t(region) >= f.regions.size()) throw Error("forecast: region index " + std::to_string(region) + " out of range");
    if (!(map_size[0] > 0 && map_size[1] > 0 && std::isfinite(map_size[0]) && std::isfinite(map_size[1])))
        throw Error("forecast: map size must be positive and finite");
    const auto& r = f.regions[size_t(region)];
    const double h0 = r.keys.front().hour;
    const double h = wrap_hour(f, hour);
    const double tau = h < h0 ? h + f.period_hours : h;
    const Vec2d total = raw_drift(f, r, h0 + f.period_hours);
    const Vec2d d = raw_drift(f, r, tau);
    Vec2d out;
    for (int a = 0; a < 2; ++a) {
        // Round the loop's drift to whole map sizes; spread the difference
        // evenly over the loop. Wrapping first keeps the numbers small.
        const double excess = total[a] - std::round(total[a] / map_size[a]) * map_size[a];
        out[a] = wrap_metres(wrap_metres(d[a], map_size[a]) - wrap_metres((tau - h0) / f.period_hours * excess, map_size[a]), map_size[a]);
    }
    return out;
}

Field2D make_weather_noise(const WeatherMapSpec& spec, const MemoryBudget* budget) {
    Field2D cov = noise2d(spec.resolution, spec.bounds, spec.period, spec.octaves, spec.gain, spec.seed, budget);
    const Vec2i type_period{{std::max(1, spec.period[0] / 2), std::max(1, spec.period[1] / 2)}};
    Field2D type = noise2d(spec.resolution, spec.bounds, type_period, std::min(spec.octaves, 3), spec.gain, spec.seed + 7919u, budget);
    Field2D out(spec.resolution, 2, spec.bounds, {"coverage_noise", "type_noise"}, budget);
    // FBM values crowd around 0.5: replace each value by its rank (histogram
    // equalisation, ties broken by index), so the noise is uniform on [0,1]
    // and a preset's cumulus_coverage c is the share of texels with
    // n > 1 - c: "coverage" means the share of the sky.
    const Field2D* src[2] = {&cov, &type};
    std::vector<uint32_t> order(cov.voxel_count());
    for (int c = 0; c < 2; ++c) {
        const auto in = src[c]->channel(0);
        for (size_t i = 0; i < order.size(); ++i) order[i] = uint32_t(i);
        std::sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return in[a] < in[b] || (in[a] == in[b] && a < b); });
        auto o = out.channel(c);
        const double n = double(order.size());
        for (size_t r = 0; r < order.size(); ++r) o[order[r]] = float((double(r) + 0.5) / n);
    }
    return out;
}

const std::vector<std::string>& weather_map_channels() {
    static const std::vector<std::string> names = {"coverage", "precipitation", "type", "cirrus_coverage"};
    return names;
}

namespace {
// One texel of a preset's map from its two noise values.
void weather_texel(const WeatherPreset& p, double n, double m, float out[4]) {
    const double c = p.cumulus_coverage;
    const double coverage = std::clamp(p.coverage_contrast * (n - (1 - c)) + c, 0.0, 1.0);
    const double precip = p.rain_intensity * smoothstep(p.rain_threshold, 1.0, coverage);
    const double base_type = std::clamp(p.cloud_type + p.type_variation * (2 * m - 1), 0.0, 1.0);
    const double storm = p.lightning * precip;
    out[0] = float(coverage);
    out[1] = float(precip);
    out[2] = float(base_type + (1 - base_type) * storm);
    out[3] = float(p.cirrus_coverage);
}

void check_noise(const Field2D& noise) {
    if (noise.channels() < 2) throw Error("weather map: the noise field needs 2 channels (coverage_noise, type_noise)");
}

// Texel coordinates of the noise read by texel (x, y) of a map with the
// noise's grid, scrolled by `drift` metres.
struct Scroll {
    double du, dv;
};
Scroll scroll_of(const Field2D& noise, Vec2d drift) {
    const Vec2d s = noise.voxel_size();
    return {drift[0] / s[0], drift[1] / s[1]};
}

// The region masks' composite weights at one texel (later regions over earlier).
void region_weights(const Forecast& f, Vec2d p, std::vector<double>& w) {
    double rest = 1;
    for (size_t r = f.regions.size(); r-- > 1;) {
        const auto& reg = f.regions[r];
        const double dx = std::min(p[0] - reg.rect.min[0], reg.rect.max[0] - p[0]);
        const double dy = std::min(p[1] - reg.rect.min[1], reg.rect.max[1] - p[1]);
        const double h = 0.5 * reg.blend;
        const double m = smoothstep(-h, h, dx) * smoothstep(-h, h, dy);
        w[r] = rest * m;
        rest *= 1 - m;
    }
    w[0] = rest;
}
} // namespace

Field2D preset_weather_map(const WeatherPreset& p, const Field2D& noise, Vec2d drift, const MemoryBudget* budget) {
    validate_preset(p);
    check_noise(noise);
    if (!std::isfinite(drift[0]) || !std::isfinite(drift[1])) throw Error("weather map: drift must be finite");
    const Vec2d size = noise.bounds().size();
    drift = Vec2d{{wrap_metres(drift[0], size[0]), wrap_metres(drift[1], size[1])}};
    Field2D out(noise.resolution(), 4, noise.bounds(), weather_map_channels(), budget);
    const Scroll s = scroll_of(noise, drift);
    parallel_for_index(noise.height(), [&](int y) {
        for (int x = 0; x < noise.width(); ++x) {
            const double u = x + 0.5 - s.du, v = y + 0.5 - s.dv;
            float t[4];
            weather_texel(p, noise.sample_texel(0, u, v, WrapMode::Wrap), noise.sample_texel(1, u, v, WrapMode::Wrap), t);
            for (int c = 0; c < 4; ++c) out.at(c, x, y) = t[c];
        }
    });
    return out;
}

Field2D forecast_weather_map(const Forecast& f, const Field2D& noise, double hour, const MemoryBudget* budget) {
    validate_forecast(f);
    check_noise(noise);
    const size_t nr = f.regions.size();
    std::vector<WeatherPreset> presets;
    std::vector<Scroll> scrolls;
    for (size_t r = 0; r < nr; ++r) {
        presets.push_back(forecast_preset(f, int(r), hour));
        scrolls.push_back(scroll_of(noise, forecast_drift(f, int(r), hour, noise.bounds().size())));
    }
    Field2D out(noise.resolution(), 4, noise.bounds(), weather_map_channels(), budget);
    parallel_for_index(noise.height(), [&](int y) {
        std::vector<double> w(nr);
        for (int x = 0; x < noise.width(); ++x) {
            region_weights(f, noise.texel_center(x, y), w);
            double acc[4] = {0, 0, 0, 0};
            for (size_t r = 0; r < nr; ++r) {
                if (w[r] == 0) continue;
                const double u = x + 0.5 - scrolls[r].du, v = y + 0.5 - scrolls[r].dv;
                float t[4];
                weather_texel(presets[r], noise.sample_texel(0, u, v, WrapMode::Wrap), noise.sample_texel(1, u, v, WrapMode::Wrap), t);
                for (int c = 0; c < 4; ++c) acc[c] += w[r] * t[c];
            }
            for (int c = 0; c < 4; ++c) out.at(c, x, y) = float(std::clamp(acc[c], 0.0, 1.0));
        }
    });
    return out;
}

namespace {
void check_sequence(double start_hour, double step_hours, int slices) {
    if (!std::isfinite(start_hour)) throw Error("forecast: start_hour must be finite");
    if (!(step_hours > 0 && std::isfinite(step_hours))) throw Error("forecast: step_hours = " + detail::number_text(step_hours) + " must be > 0");
    if (slices < 1 || slices > 100000) throw Error("forecast: slices = " + std::to_string(slices) + " is out of range [1, 100000]");
}
} // namespace

Field3D cook_forecast(const Forecast& f, const WeatherMapSpec& spec, double start_hour, double step_hours, int slices,
                      const MemoryBudget* budget, const ProgressSink* progress) {
    validate_forecast(f);
    check_sequence(start_hour, step_hours, slices);
    const Field2D noise = make_weather_noise(spec, budget);
    const Box3d box{{{spec.bounds.min[0], spec.bounds.min[1], 0}}, {{spec.bounds.max[0], spec.bounds.max[1], double(slices)}}};
    Field3D out({{spec.resolution[0], spec.resolution[1], slices}}, 4, box, weather_map_channels(), budget);
    const size_t plane = size_t(spec.resolution[0]) * size_t(spec.resolution[1]);
    for (int i = 0; i < slices; ++i) {
        const Field2D m = forecast_weather_map(f, noise, start_hour + i * step_hours, budget);
        for (int c = 0; c < 4; ++c)
            std::copy(m.channel(c).begin(), m.channel(c).end(), out.channel(c).begin() + std::ptrdiff_t(plane * size_t(i)));
        if (progress) {
            if (progress->on_progress) progress->on_progress({"forecast slices", double(i + 1) / slices, i + 1, slices});
            progress->poll();
        }
    }
    return out;
}

std::string forecast_manifest_json(const Forecast& f, const WeatherMapSpec& spec, double start_hour, double step_hours, int slices) {
    validate_forecast(f);
    check_sequence(start_hour, step_hours, slices);
    using J = nlohmann::ordered_json;
    J j;
    j["atlas_forecast_sequence"] = 1;
    j["period_hours"] = f.period_hours;
    j["transition_hours"] = f.transition_hours;
    // Every field's transition length (0: the whole gap between keys), overrides applied.
    J lengths;
    for (const auto& t : transition_fields()) lengths[t.name] = field_transition(f, t.name);
    j["field_transition_hours"] = lengths;
    j["start_hour"] = start_hour;
    j["step_hours"] = step_hours;
    j["slices"] = slices;
    j["resolution"] = {spec.resolution[0], spec.resolution[1]};
    j["bounds"] = {{"min", {spec.bounds.min[0], spec.bounds.min[1]}}, {"max", {spec.bounds.max[0], spec.bounds.max[1]}}};
    j["channels"] = weather_map_channels();
    J regions = J::array();
    for (const auto& r : f.regions) {
        J jr;
        jr["name"] = r.name;
        if (r.whole_map)
            jr["rect"] = nullptr;
        else
            jr["rect"] = {r.rect.min[0], r.rect.min[1], r.rect.max[0], r.rect.max[1]};
        jr["blend_m"] = r.blend;
        regions.push_back(jr);
    }
    j["regions"] = regions;
    J frames = J::array();
    for (int i = 0; i < slices; ++i) {
        const double hour = start_hour + i * step_hours;
        const double h = wrap_hour(f, hour);
        J fr;
        fr["slice"] = i;
        fr["hour"] = hour;
        fr["forecast_hour"] = h;
        fr["day"] = int(std::floor(h / 24));
        J per = J::array();
        for (size_t r = 0; r < f.regions.size(); ++r) {
            const PresetBlend b = forecast_blend(f, int(r), hour);
            const WeatherPreset p = forecast_preset(f, int(r), hour);
            const Vec2d d = forecast_drift(f, int(r), hour, spec.bounds.size());
            J jr;
            jr["region"] = f.regions[r].name;
            jr["presets"] = J::array({J{{"name", f.presets[size_t(b.from)].name}, {"weight", 1 - b.weight}},
                                      J{{"name", f.presets[size_t(b.to)].name}, {"weight", b.weight}}});
            jr["drift_m"] = {d[0], d[1]};
            if (!f.field_transition_hours.empty()) {
                // The share of the second preset per overridden field (the others have the preset weight).
                J weights;
                for (const auto& [name, hours] : f.field_transition_hours) weights[name] = forecast_field_weight(f, int(r), hour, name);
                jr["field_weights"] = weights;
            }
            J values;
            for (const auto& fi : preset_fields()) values[fi.name] = p.*fi.member;
            jr["values"] = values;
            per.push_back(jr);
        }
        fr["regions"] = per;
        frames.push_back(fr);
    }
    j["frames"] = frames;
    return j.dump(1) + "\n";
}

Field2D forecast_manifest_table(const Forecast& f, const WeatherMapSpec& spec, double start_hour, double step_hours, int slices) {
    validate_forecast(f);
    check_sequence(start_hour, step_hours, slices);
    std::vector<std::string> names = {"hour", "from", "to", "weight", "drift_x", "drift_y"};
    for (const auto& p : f.presets) names.push_back("preset:" + p.name);
    for (const auto& fi : preset_fields()) names.push_back(fi.name);
    // Per transition field: its length (hours; 0 = the whole gap) and its share of `to`.
    for (const auto& tf : transition_fields()) names.push_back("transition:" + tf.name);
    for (const auto& tf : transition_fields()) names.push_back("weight:" + tf.name);
    const int nr = int(f.regions.size());
    Field2D t({{slices, nr}}, int(names.size()), Box2d{{{0, 0}}, {{double(slices), double(nr)}}}, names);
    for (int i = 0; i < slices; ++i)
        for (int r = 0; r < nr; ++r) {
            const double hour = start_hour + i * step_hours;
            const PresetBlend b = forecast_blend(f, r, hour);
            const WeatherPreset p = forecast_preset(f, r, hour);
            const Vec2d d = forecast_drift(f, r, hour, spec.bounds.size());
            int c = 0;
            for (double v : {hour, double(b.from), double(b.to), b.weight, d[0], d[1]}) t.at(c++, i, r) = float(v);
            t.at(c + b.from, i, r) += float(1 - b.weight);
            t.at(c + b.to, i, r) += float(b.weight);
            c += int(f.presets.size());
            for (const auto& fi : preset_fields()) t.at(c++, i, r) = float(p.*fi.member);
            for (const auto& tf : transition_fields()) t.at(c++, i, r) = float(field_transition(f, tf.name));
            for (const auto& tf : transition_fields()) t.at(c++, i, r) = float(forecast_field_weight(f, r, hour, tf.name));
        }
    return t;
}

} // namespace atlas::ndf

// atlas/ndf/forecast.h - Far Cry 6 style weather forecast and its cook into
// a sequence of weather maps (GDC 2022: "each game region can have a looping
// forecast of 5 days", presets keyed by the hour).
//
// Forecast file (YAML, docs/ndf.md "Weather forecast"):
//
//   atlas_forecast: 1
//   presets: presets.yaml          # relative to this file
//   period_hours: 120              # the forecast loops (5 days)
//   transition_hours: 3            # 0: blend over the whole gap between keys
//   field_transition_hours:        # optional, per field (transition_fields())
//     cumulus_coverage: 6          #   clouds build up before the rain ...
//     rain_intensity: 1            #   ... which starts late and fast
//   regions:
//     - name: central              # region 0 covers the whole map
//       keys: [[0, mist], [6, broken_clouds], [30, light_rain]]
//     - name: east
//       rect: [30000, 0, 60000, 60000]   # metres: xmin ymin xmax ymax
//       blend: 8000                      # metres across the border
//       keys: [[0, thunderstorm], [48, overcast]]
//
// Time: hour t is taken modulo period_hours. Between key i (hour h_i) and
// key i+1 (the last key wraps to the first + period) the preset is
// lerp_presets(P_i, P_i+1, smoothstep(h_i+1 - L, h_i+1, t)), L = the gap, or
// transition_hours when that is shorter; a field of field_transition_hours
// blends over its own length the same way. A keyed hour gives its preset
// exactly. Everything here is pure, thread-safe and deterministic.
#pragma once

#include "atlas/core/field.h"
#include "atlas/core/memory.h"
#include "atlas/core/progress.h"
#include "atlas/ndf/weather_preset.h"

#include <map>
#include <string>
#include <vector>

namespace atlas::ndf {

struct ForecastKey {
    double hour = 0; // [0, period_hours), strictly increasing within a region
    int preset = 0;  // index into Forecast::presets
};

struct ForecastRegion {
    std::string name;
    bool whole_map = true;         // region 0 must be; later regions have a rect
    Box2d rect{};                  // metres (world XY), when !whole_map
    double blend = 0;              // metres (>= 0): width of the smooth border, centred on the rect edge
    std::vector<ForecastKey> keys; // at least one
};

struct Forecast {
    double period_hours = 120;   // (0, 10000]: the loop length
    double transition_hours = 0; // >= 0; 0 = the whole gap between keys
    // Per-field lengths (hours >= 0; 0 = the whole gap) that override transition_hours,
    // by transition_fields() name: 002's "natural transitions" (a storm preceded by
    // darkening clouds) need coverage to change before the rain does.
    std::map<std::string, double> field_transition_hours;
    std::vector<WeatherPreset> presets;
    std::vector<ForecastRegion> regions; // >= 1; later regions lie over earlier ones
};

// The names field_transition_hours takes, each with the preset fields it blends:
// every preset field, but "wind" for wind_speed and wind_direction (one velocity,
// which the drift integrates) and "heights" for min_height and max_height (kept
// ordered).
struct TransitionField {
    std::string name;
    std::vector<std::string> fields;
};
const std::vector<TransitionField>& transition_fields();
// The transition length of a transition_fields() name: its override, else transition_hours.
double field_transition(const Forecast& f, const std::string& name);

// Throws atlas::Error naming the region/key: no regions, region 0 with a
// rect, a later region without one, no keys, hours out of [0, period) or
// not strictly increasing, preset indices out of range, bad period/transition,
// a field_transition_hours name that is not a transition field or a length < 0.
void validate_forecast(const Forecast& f);

// Parses a forecast file's text; presets come from `presets` (the caller
// loaded them). Errors are atlas::ParseError at file:line:col naming the
// field, e.g. "region 'east': key hour 12 is not after the previous key (30)".
// The 'presets:' entry is not read here (forecast_presets_entry gives it).
Forecast parse_forecast(const std::string& text, const std::string& filename, std::vector<WeatherPreset> presets);

// The presets file a forecast's text names in its 'presets:' entry, as written
// (a path relative to the forecast file's directory; the caller resolves and
// reads it: files are read in io and the nodes, not here). ParseError at
// file:line when the entry is missing or not a non-empty string.
std::string forecast_presets_entry(const std::string& text, const std::string& filename);

// Which two presets are blended at `hour` in `region`: weight is the share
// of `to` (0 at a key). A single-key region gives {k, k, 0}.
struct PresetBlend {
    int from = 0, to = 0;
    double weight = 0;
};
// The weight is transition_hours' (the fields without an override).
PresetBlend forecast_blend(const Forecast& f, int region, double hour);
// The share of `to` for one transition_fields() name (its own length).
double forecast_field_weight(const Forecast& f, int region, double hour, const std::string& name);
// The blended preset: lerp_presets of the blend above, each overridden field at its own weight.
WeatherPreset forecast_preset(const Forecast& f, int region, double hour);

// How far the region's weather map has scrolled with its wind at `hour`
// (metres, each axis wrapped into [0, map_size)). The wind velocity is
// integrated exactly over the smoothstep blends; the drift of a whole loop
// is rounded to whole map sizes by a constant correction (at most
// map_size / (2 period) per hour), so hour = period gives drift 0 again:
// the scroll loops without a jump.
Vec2d forecast_drift(const Forecast& f, int region, double hour, Vec2d map_size);

// The tiling weather map's noises and grid.
struct WeatherMapSpec {
    Vec2i resolution{{256, 256}};
    Box2d bounds{{{0, 0}}, {{60000, 60000}}}; // metres
    Vec2i period{{6, 6}};                     // coverage noise lattice cells across the map (the type noise uses half, at least 1)
    int octaves = 5;                          // [1, 16]
    double gain = 0.55;                       // [0, 1]
    uint32_t seed = 0;
};

// Two tileable noise channels ("coverage_noise", "type_noise"): value-noise
// FBMs (noise2d), each histogram-equalised (texel -> (rank + 0.5) / count,
// ties by index), so each is uniform on (0,1).
Field2D make_weather_noise(const WeatherMapSpec& spec, const MemoryBudget* budget);

// Channel names of a weather map: coverage, precipitation, type, cirrus_coverage.
const std::vector<std::string>& weather_map_channels();

// A preset's weather map, its noise scrolled by `drift` (metres; texel
// p reads the noise at p - drift, wrapped):
//   coverage      = clamp(contrast (n - (1 - c)) + c, 0, 1)   n: coverage noise, c: cumulus_coverage
//   precipitation = rain_intensity * smoothstep(rain_threshold, 1, coverage)
//   type          = lerp(clamp(cloud_type + type_variation (2 m - 1)), 1, lightning * precipitation)
//   cirrus_coverage = cirrus_coverage
// c = 0 gives coverage 0 and c = 1 coverage 1 everywhere.
Field2D preset_weather_map(const WeatherPreset& p, const Field2D& noise, Vec2d drift, const MemoryBudget* budget);

// The forecast's map at `hour`: per region, its preset's map with its own
// drift; regions composited over region 0 by their border masks
// (m = s(dx) s(dy), s = smoothstep(-blend/2, blend/2, distance inside the rect)).
Field2D forecast_weather_map(const Forecast& f, const Field2D& noise, double hour, const MemoryBudget* budget);

// The sequence: slice i at hour start + i * step, as a Field3D whose z is
// the slice (z bounds = [0, slices), 4 channels as above) - written as a
// DDS texture array. slices in [1, 100000], step > 0. Progress per slice.
Field3D cook_forecast(const Forecast& f, const WeatherMapSpec& spec, double start_hour, double step_hours, int slices,
                      const MemoryBudget* budget, const ProgressSink* progress);

// The manifest: JSON text listing each slice's hour, day, and per region
// the two presets, the weight of the second, the drift and the blended
// preset's fields (docs/formats.md "Forecast sequence").
std::string forecast_manifest_json(const Forecast& f, const WeatherMapSpec& spec, double start_hour, double step_hours, int slices);

// The same per (slice, region) as a table field, width = slices, height =
// regions, channels: hour, from, to (preset indices), weight (of `to`),
// drift_x, drift_y (m), then "preset:NAME" = the weight of each preset
// (summing to 1), then every preset field (preset_fields() order) - for
// graph outputs (json/exr).
Field2D forecast_manifest_table(const Forecast& f, const WeatherMapSpec& spec, double start_hour, double step_hours, int slices);

} // namespace atlas::ndf

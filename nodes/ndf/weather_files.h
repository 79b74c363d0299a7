// Shared by ndf/weather_preset and ndf/forecast (not a node): reading their
// files. ndf parses text in memory; the nodes read the files it names.
#pragma once

#include "atlas/core/files.h"
#include "atlas/ndf/forecast.h"
#include "atlas/ndf/weather_preset.h"

#include <string>
#include <vector>

namespace atlas::ndf_nodes {

inline std::vector<ndf::WeatherPreset> read_presets_file(const fs::path& file) {
    return ndf::parse_presets(read_file_bytes(file), file.string());
}

// The presets file a forecast names, relative to the forecast file's directory.
inline fs::path forecast_presets_file(const fs::path& forecast_file, const std::string& forecast_text) {
    return forecast_file.parent_path() / ndf::forecast_presets_entry(forecast_text, forecast_file.string());
}

inline ndf::Forecast read_forecast_file(const fs::path& file) {
    const std::string text = read_file_bytes(file);
    return ndf::parse_forecast(text, file.string(), read_presets_file(forecast_presets_file(file, text)));
}

} // namespace atlas::ndf_nodes

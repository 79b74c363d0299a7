// The "dds" output format: graph outputs encoded through the error-bounded
// compressor (atlas/compress/texture.h), with the same options as
// `atlas compress`. Writes OUT.dds and its manifest OUT.dds.json.
#include "atlas/compress/compress_options.h"
#include "atlas/compress/texture.h"
#include "atlas/io/dds_file.h"
#include "atlas/io/output_options.h"
#include "atlas/io/readers.h"
#include "format_table.h"

#include <cstdio>

namespace atlas::io::detail {

namespace {
// Every option through the compress schema (atlas/compress/compress_options.h), the
// one `atlas compress` parses its flags with; channel names are resolved against
// the value when it is written.
compress::CompressOptions dds_options(const OptionReader& o) {
    compress::CompressOptions c;
    c.format = compress::kDdsOutputDefaultFormat;
    for (const auto& option : compress::compress_options())
        if (o.has(option.name) && !set_text_option(option, o.text(option.name), c)) o.bad(option.name, option.expected());
    return c;
}
} // namespace

void check_dds_options(const OptionReader& o, const fs::path&, PortType) { dds_options(o); }

std::vector<fs::path> write_dds_output(const Value& value, const fs::path& path, const OutputOptions& options, OutputMetrics& metrics) {
    const OptionReader o(options, path);
    const Field3DPtr field = as_field3d(value);
    compress::CompressOptions c = dds_options(o);
    try {
        compress::resolve_channel_names(c, *field);
    } catch (const Error& e) {
        throw Error(o.prefix() + e.what());
    }
    const compress::CompressReport r = io::compress_to_dds(*field, path, c);
    // Error against run time, for the cook report.
    for (size_t ch = 0; ch < r.max_error.size(); ++ch) {
        metrics["max_error_" + std::to_string(ch)] = r.max_error[ch];
        metrics["rmse_" + std::to_string(ch)] = r.rmse[ch];
    }
    metrics["bound_max_error"] = r.bound_max_error;
    metrics["blocks_over_bound"] = double(r.blocks_over_bound.size());
    metrics["encode_seconds"] = r.encode_seconds;
    metrics["verify_seconds"] = r.verify_seconds;
    return {path, fs::path(path.string() + ".json")};
}

} // namespace atlas::io::detail

namespace atlas::io {

bool output_maps_by_own_range(const std::string& format, const OutputOptions& options) {
    return format == "dds" && compress::maps_by_own_range(detail::dds_options(OptionReader(options, "output")));
}

std::optional<std::pair<float, float>> output_own_range(const Value& value, const std::string& format, const OutputOptions& options) {
    if (!output_maps_by_own_range(format, options)) return std::nullopt;
    compress::CompressOptions c = detail::dds_options(OptionReader(options, "output"));
    const Field3DPtr field = as_field3d(value);
    compress::resolve_channel_names(c, *field);
    return compress::own_value_range(*field, c);
}

OutputOptions with_range(OutputOptions options, std::pair<float, float> range) {
    // %.9g round-trips a float exactly, so the tile maps by the very range given.
    char text[64];
    std::snprintf(text, sizeof text, "%.9g,%.9g", double(range.first), double(range.second));
    options["range"] = text;
    return options;
}

} // namespace atlas::io

// The "dds" output format: graph outputs encoded through the error-bounded
// compressor (atlas/compress/texture.h), with the same options as
// `atlas compress`. Writes OUT.dds and its manifest OUT.dds.json.
#include "atlas/compress/texture.h"
#include "atlas/io/output_options.h"
#include "atlas/io/readers.h"
#include "format_table.h"

namespace atlas::io::detail {

namespace {
// Every option except the channel names' existence (checked when the graph loads too).
compress::CompressOptions dds_options(const OptionReader& o) {
    compress::CompressOptions c;
    try {
        c.format = compress::parse_format(o.has("encoding") ? o.text("encoding") : std::string("rgba16f"));
        if (o.has("quality")) c.quality = compress::parse_quality(o.text("quality").c_str());
        if (o.has("decoders")) {
            c.decoders = 0;
            for (const auto& d : o.list("decoders")) c.decoders |= compress::decoder_bit(compress::parse_decoder(d));
        }
    } catch (const Error& e) {
        throw Error(o.prefix() + e.what());
    }
    if (o.has("max_error")) c.max_error = o.number("max_error", 0.0f, 0.0f, INFINITY);
    if (o.has("one_sided")) {
        if (o.text("one_sided") != "below") o.bad("one_sided", "'below'");
        c.one_sided_below = true;
    }
    c.allow_over_bound = o.flag("allow_over_bound");
    if (o.has("mips")) c.mip_levels = o.text("mips") == "full" ? 0 : o.integer("mips", 1, 1, compress::kMaxMipLevels);
    if (o.has("range")) c.value_range = o.range("range", 0.0f, 1.0f);
    o.list("channels");
    c.as_array = o.flag("array");
    return c;
}
} // namespace

void check_dds_options(const OptionReader& o, const fs::path&, PortType) { dds_options(o); }

std::vector<fs::path> write_dds_output(const Value& value, const fs::path& path, const OutputOptions& options, OutputMetrics& metrics) {
    const OptionReader o(options, path);
    const Field3DPtr field = as_field3d(value);
    compress::CompressOptions c = dds_options(o);
    for (const auto& name : o.list("channels")) {
        const int ch = field->find_channel(name);
        if (ch < 0) o.bad("channels", "names of the value's channels");
        c.channels.push_back(ch);
    }
    const compress::CompressReport r = compress::compress_to_dds(*field, path, c);
    // Error against run time, for the cook report.
    for (size_t ch = 0; ch < r.max_error.size(); ++ch) {
        metrics["max_error_" + std::to_string(ch)] = r.max_error[ch];
        metrics["rmse_" + std::to_string(ch)] = r.rmse[ch];
    }
    metrics["bound_max_error"] = r.bound_max_error;
    metrics["blocks_over_bound"] = double(r.blocks_over_bound.size());
    metrics["encode_seconds"] = r.encode_seconds;
    return {path, fs::path(path.string() + ".json")};
}

} // namespace atlas::io::detail

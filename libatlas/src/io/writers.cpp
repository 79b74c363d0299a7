// Output dispatch: format lookup, value-type and option-name checks.
#include "atlas/io/writers.h"

#include "atlas/core/error.h"
#include "format_table.h"

#include <algorithm>

namespace atlas::io {

namespace {
std::string prefix(const fs::path& path) { return "output '" + path.filename().string() + "': "; }
} // namespace

const std::vector<OutputFormat>& output_formats() {
    static const std::vector<OutputFormat> formats = [] {
        std::vector<OutputFormat> v;
        for (const auto& e : detail::format_table()) v.push_back(e.format);
        return v;
    }();
    return formats;
}

std::string output_format_for_path(const fs::path& path) {
    std::string ext = path.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    std::string known;
    for (const auto& e : detail::format_table())
        for (const auto& x : e.format.extensions) {
            if (x == ext) return e.format.name;
            known += (known.empty() ? "" : ", ") + x;
        }
    throw Error("output '" + path.string() + "': cannot tell the format from the extension" + (ext.empty() ? "" : " '" + ext + "'") +
                " (known: " + known + "); name the format explicitly (e.g. format: tga-slices)");
}

void check_output_options(const std::string& format, const fs::path& path, const OutputOptions& options, PortType produced) {
    const auto& table = detail::format_table();
    const auto it = std::find_if(table.begin(), table.end(), [&](const detail::FormatEntry& e) { return e.format.name == format; });
    if (it == table.end() || !it->check) return;
    it->check(OptionReader(options, path), path, produced);
}

std::vector<fs::path> write_value(const Value& value, const fs::path& path, const std::string& format, const OutputOptions& options,
                                  OutputMetrics* metrics) {
    const auto& table = detail::format_table();
    const auto it = std::find_if(table.begin(), table.end(), [&](const detail::FormatEntry& e) { return e.format.name == format; });
    if (it == table.end()) {
        std::string names;
        for (const auto& e : table) names += (names.empty() ? "" : ", ") + e.format.name;
        throw Error(prefix(path) + "unknown format '" + format + "' (known: " + names + ")");
    }
    const OutputFormat& f = it->format;
    std::string accepts;
    for (PortType t : f.accepts) accepts += (accepts.empty() ? "" : " or ") + std::string(port_type_name(t));
    if (std::holds_alternative<std::monostate>(value)) throw Error(prefix(path) + "the value is empty; format '" + format + "' writes " + accepts);
    const PortType t = value_type(value);
    if (std::find(f.accepts.begin(), f.accepts.end(), t) == f.accepts.end())
        throw Error(prefix(path) + "format '" + format + "' writes " + accepts + ", not a " + std::string(port_type_name(t)));
    for (const auto& kv : options) {
        const bool known = std::any_of(f.options.begin(), f.options.end(), [&](const auto& o) { return o.first == kv.first; });
        if (!known) {
            std::string list;
            for (const auto& o : f.options) list += (list.empty() ? "" : ", ") + o.first;
            throw Error(prefix(path) + "unknown option '" + kv.first + "' (known: " + list + ")");
        }
    }
    OutputMetrics measured;
    auto files = it->write(value, path, options, measured);
    if (metrics) *metrics = std::move(measured);
    return files;
}

} // namespace atlas::io

// Private: the table behind output_formats() and write_value().
//
// Adding a format (e.g. DDS) = one writer function in its own .cpp file,
// declared here, plus one entry appended in format_table.cpp. write_value()
// checks the value type against `accepts` and the option names against
// `options` before calling the writer, so a writer only parses values
// (through OptionReader) and writes.
#pragma once

#include "atlas/io/output_options.h"
#include "atlas/io/writers.h"

namespace atlas::io::detail {

// Writes `value` (of a type the format accepts) to `path`; returns the files written.
// A writer may record error metrics it measured in `metrics`.
using FormatWriter = std::vector<fs::path> (*)(const Value& value, const fs::path& path, const OutputOptions& options,
                                               OutputMetrics& metrics);

// Checks the options that do not depend on the value (parses them as the
// writer does; throws atlas::Error naming the option), for the type of value
// the graph's port produces. Run when the graph loads, before anything cooks.
using FormatChecker = void (*)(const OptionReader& options, const fs::path& path, PortType produced);

struct FormatEntry {
    OutputFormat format;
    FormatWriter write;
    FormatChecker check;
};

// In a fixed order: the order of output_formats().
const std::vector<FormatEntry>& format_table();

// The writers (format_writers.cpp).
std::vector<fs::path> write_exr_output(const Value&, const fs::path&, const OutputOptions&, OutputMetrics&);
std::vector<fs::path> write_image_output(const Value&, const fs::path&, const OutputOptions&, OutputMetrics&);
std::vector<fs::path> write_vdb_output(const Value&, const fs::path&, const OutputOptions&, OutputMetrics&);
std::vector<fs::path> write_tga_slices_output(const Value&, const fs::path&, const OutputOptions&, OutputMetrics&);
// dds_output.cpp: through atlas::compress.
std::vector<fs::path> write_dds_output(const Value&, const fs::path&, const OutputOptions&, OutputMetrics&);

void check_exr_options(const OptionReader&, const fs::path&, PortType);
void check_image_options(const OptionReader&, const fs::path&, PortType);
void check_vdb_options(const OptionReader&, const fs::path&, PortType);
void check_tga_slices_options(const OptionReader&, const fs::path&, PortType);
void check_dds_options(const OptionReader&, const fs::path&, PortType);

} // namespace atlas::io::detail

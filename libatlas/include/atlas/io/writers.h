// atlas/io/writers.h - the output formats a graph (or the CLI) can write.
//
// The table of formats is the single source for validation (graph outputs
// are checked against it before anything cooks), for docs, and for dispatch.
// Writers write straight to the path given; atomicity is the caller's job
// (core/files.h StagedOutputs).
#pragma once

#include "atlas/core/value.h"

#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace atlas::io {

namespace fs = std::filesystem;

// Option name -> value text, as given in a graph output's `options` map.
using OutputOptions = std::map<std::string, std::string>;

struct OutputFormat {
    std::string name;                                          // "exr"
    std::vector<std::string> extensions;                       // {".exr"}
    std::vector<PortType> accepts;                             // value types it writes
    std::string doc;                                           // one line
    std::vector<std::pair<std::string, std::string>> options;  // option name, doc
    // The writer's version: part of every output's key, so files written by an
    // older writer (other bytes for the same value and options) are written again.
    int version = 1;
};

// Every output format, in a fixed order.
const std::vector<OutputFormat>& output_formats();

// The format for a file name's extension; throws atlas::Error listing the
// known extensions when there is none.
std::string output_format_for_path(const fs::path& path);

// Writes `value` in `format` to `path` and returns the files written (several
// for "tga-slices", where `path` is DIR/STEM and files are DIR/STEM.001.tga...).
// Throws atlas::Error on a value the format cannot write, an unknown option
// or a bad option value (naming the option and what it expects).
// Error metrics a writer measured (e.g. a DDS encode's max error), name -> value.
using OutputMetrics = std::map<std::string, double>;

// Checks the option values of an output that do not depend on the value
// itself (an option's type and range, contradicting options), for a port
// producing `produced`: what a graph load can refuse before anything cooks.
// Throws atlas::Error "output 'NAME': option 'key': expected ..., got '...'".
// Option names are not checked here (the caller lists the known ones).
void check_output_options(const std::string& format, const fs::path& path, const OutputOptions& options, PortType produced);

std::vector<fs::path> write_value(const Value& value, const fs::path& path, const std::string& format, const OutputOptions& options,
                                  OutputMetrics* metrics = nullptr);

// Outputs that quantise a value by its own range (a "dds" in a normalised format without
// option 'range', compress::maps_by_own_range): a tile of such an output would be
// quantised differently from its neighbours. A tiled cook records each tile's
// output_own_range and rewrites the tiles with their union as 'range'
// (with_range) so that they quantise as the whole world does (docs/scale.md).
bool output_maps_by_own_range(const std::string& format, const OutputOptions& options);
std::optional<std::pair<float, float>> output_own_range(const Value& value, const std::string& format, const OutputOptions& options);
OutputOptions with_range(OutputOptions options, std::pair<float, float> range); // 'range' set exactly ("%.9g,%.9g")

} // namespace atlas::io

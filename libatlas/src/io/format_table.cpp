// The output formats, their options and their writers. Append new formats at
// the end (the order is what `atlas` and docs list).
#include "format_table.h"

#include "atlas/compress/compress_options.h"
#include "atlas/compress/texture.h"
#include "atlas/core/error.h"
#include "atlas/core/files.h"
#include "atlas/io/output_options.h"

#include <nlohmann/json.hpp>

#include <charconv>
#include <cmath>
#include <fstream>
#include <limits>

namespace atlas::io::detail {

namespace {
const std::pair<std::string, std::string> kChannels{"channels", "comma-separated channel names to write, in this order (default: all)"};

// The double nearest the float's shortest decimal form: JSON shows 0.05, not
// 0.05000000074505806, and parsing it back as float gives the same float.
double shortest(float v) {
    char buf[32];
    const auto r = std::to_chars(buf, buf + sizeof buf, v);
    double d = 0;
    std::from_chars(buf, r.ptr, d);
    return d;
}

// A small 2D field (a table such as the vortex-ring sidecar) as JSON text:
// float values as JSON numbers (shortest round-trip form), NaN/Inf as null.
std::vector<fs::path> write_json_output(const Value& v, const fs::path& p, const OutputOptions& opts, OutputMetrics&) {
    const OptionReader o(opts, p);
    const Field2D& f = *std::get<Field2DPtr>(v);
    const uint64_t texels = uint64_t(f.width()) * uint64_t(f.height());
    if (texels > 65536) throw Error(o.prefix() + "a JSON table holds at most 65536 texels, the field has " + std::to_string(texels));
    std::vector<int> idx;
    for (const auto& n : o.list("channels")) {
        const int c = f.find_channel(n);
        if (c < 0) o.bad("channels", "channel names of the value");
        idx.push_back(c);
    }
    if (idx.empty())
        for (int c = 0; c < f.channels(); ++c) idx.push_back(c);
    nlohmann::ordered_json j;
    j["resolution"] = {f.width(), f.height()};
    j["bounds"] = {{"min", {f.bounds().min[0], f.bounds().min[1]}}, {"max", {f.bounds().max[0], f.bounds().max[1]}}};
    j["center"] = {0.5 * (f.bounds().min[0] + f.bounds().max[0]), 0.5 * (f.bounds().min[1] + f.bounds().max[1])};
    auto& names = j["channels"] = nlohmann::ordered_json::array();
    for (int c : idx) names.push_back(f.channel_name(c));
    auto& rows = j["rows"] = nlohmann::ordered_json::array();
    for (int y = 0; y < f.height(); ++y)
        for (int x = 0; x < f.width(); ++x) {
            nlohmann::ordered_json row;
            row["x"] = x;
            row["y"] = y;
            for (int c : idx) {
                const float val = f.at(c, x, y);
                row[f.channel_name(c)] = std::isfinite(val) ? nlohmann::ordered_json(shortest(val)) : nlohmann::ordered_json(nullptr);
            }
            rows.push_back(std::move(row));
        }
    const std::string text = j.dump(1) + "\n";
    // write_file_checked names the system's reason (a full disk, a size limit).
    write_file_atomic(p, [&](const fs::path& tmp) {
        try {
            write_file_checked(tmp, text.data(), text.size());
        } catch (const Error& e) {
            throw Error(o.prefix() + "cannot write " + p.filename().string() + ": " + e.what());
        }
    });
    return {p};
}
// The dds output's option docs: the compress schema's (atlas compress takes the same values).
std::vector<std::pair<std::string, std::string>> dds_option_docs() {
    std::vector<std::pair<std::string, std::string>> docs;
    for (const auto& o : compress::compress_options()) docs.emplace_back(o.name, o.doc + "; " + o.expected());
    return docs;
}
} // namespace

void check_json_options(const OptionReader& o, const fs::path&, PortType) { o.list("channels"); }

// vdb_sequence.cpp
std::vector<fs::path> write_vdb_sequence_output(const Value&, const fs::path&, const OutputOptions&, OutputMetrics&);
void check_vdb_sequence_options(const OptionReader& o, const fs::path&, PortType) {
    o.number("tolerance", 0.0f, 0.0f, std::numeric_limits<float>::infinity());
}

const std::vector<FormatEntry>& format_table() {
    static const std::vector<FormatEntry> table = {
        {{"exr",
          {".exr"},
          {PortType::Field2D, PortType::Field3D},
          "OpenEXR, 32-bit float (bit-exact) or half; a 3D field is nx x (ny*nz) stacked slices with atlas:* header attributes",
          {{"half", "true: store 16-bit half floats (values beyond +-65504 are an error)"},
           {"meaning", "free text stored in the atlas:channel_meaning attribute"},
           {"compression", "zip (default) or none: data that does not compress (an SDF's float mantissas) writes faster uncompressed"},
           kChannels}},
         write_exr_output,
         check_exr_options},
        {{"png",
          {".png"},
          {PortType::Field2D, PortType::Field3D},
          "PNG, 8 or 16 bits, 1-4 channels, values mapped from 'range'; a 3D field writes one z slice or a montage",
          {{"bits", "8 or 16 (default 8)"},
           {"range", "'lo,hi': the values mapped to 0 and to full scale (default 0,1); outside values clamp"},
           {"slice", "3D fields: the z index to write (default nz/2)"},
           {"montage", "3D fields: true writes every slice tiled in a grid (slice 0 top left)"},
           kChannels}},
         write_image_output,
         check_image_options},
        {{"tga",
          {".tga"},
          {PortType::Field2D, PortType::Field3D},
          "TGA, 8 bits, 1, 3 or 4 channels, uncompressed, values mapped from 'range'; a 3D field writes one z slice or a montage",
          {{"bits", "8 (TGA holds 8 bits per channel)"},
           {"range", "'lo,hi': the values mapped to 0 and 255 (default 0,1); outside values clamp"},
           {"slice", "3D fields: the z index to write (default nz/2)"},
           {"montage", "3D fields: true writes every slice tiled in a grid (slice 0 top left)"},
           kChannels}},
         write_image_output,
         check_image_options},
        {{"vdb",
          {".vdb"},
          {PortType::Field3D},
          "OpenVDB, one sparse float fog-volume grid per channel (named after it), voxel centres as in the field",
          {{"tolerance", "values with |v| <= tolerance stay inactive (background 0; default 0)"},
           {"vector3", "true: a 3-channel field becomes one vec3s grid"},
           {"grids", "comma-separated grid names (default: the channel names)"},
           kChannels}},
         write_vdb_output,
         check_vdb_options},
        {{"tga-slices",
          {},
          {PortType::Field3D},
          "a stack of TGA files, one per z (the Nubis voxel cloud pack layout: 32-bit RGBA, RLE); the path is DIR/STEM",
          {{"range", "'lo,hi': the values mapped to 0 and 255 (default 0,1); outside values clamp"},
           {"alpha", "0..255: alpha where the field has no 4th channel (default 255; pixels rgba only)"},
           {"channels", "comma-separated channel names for R, G, B, A (up to 4; missing ones fill with 0, alpha with 'alpha')"},
           {"naming", "atlas: STEM.001.tga, STEM.002.tga, ... (default); nubis: STEM(0).tga, STEM(1).tga, ... as the pack's own files"},
           {"compression", "rle (default, TGA image type 10/11, what the pack uses) or none (type 2/3)"},
           {"pixels", "rgba (32-bit, default), rgb (24-bit) or gray (8-bit, R only)"}}},
         write_tga_slices_output,
         check_tga_slices_options},
        {{"dds",
          {".dds"},
          {PortType::Field2D, PortType::Field3D},
          "DDS texture (2D, array or volume) through the error-bounded compressor, with its manifest FILE.dds.json",
          dds_option_docs(),
          compress::kEncoderVersion},
         write_dds_output,
         check_dds_options},
        {{"json",
          {".json"},
          {PortType::Field2D},
          "a small 2D field (at most 65536 texels) as a JSON table, e.g. a sidecar: resolution, world bounds and their centre, "
          "channel names, and rows [{x, y, <channel>: value, ...}] with x fastest (NaN/Inf as null)",
          {kChannels}},
         write_json_output,
         check_json_options},
        {{"vdb-sequence",
          {},
          {PortType::Field3D},
          "one VDB per frame, DIR/STEM.NNNN.vdb, from channels named NNNN:GRID (sim/cloud_growth's 'sequence'); GRID.x/.y/.z "
          "become one vec3s grid GRID, others float fog volumes; the path is DIR/STEM",
          {{"tolerance", "values with |v| <= tolerance stay inactive (background 0; default 0)"}}},
         write_vdb_sequence_output,
         check_vdb_sequence_options},
    };
    return table;
}

} // namespace atlas::io::detail

#include "atlas/io/writers.h"

#include "atlas/core/error.h"
#include "atlas/io/exr.h"
#include "atlas/io/image.h"
#include "atlas/io/tga_slices.h"
#include "atlas/io/vdb.h"

#include <algorithm>
#include <charconv>
#include <sstream>

namespace atlas::io {

namespace {

using Writer = std::vector<fs::path> (*)(const Value&, const fs::path&, const OutputOptions&);

// Typed access to option text, with errors that say what was expected.
struct Options {
    const OutputOptions& map;
    const fs::path& path;

    bool has(const std::string& k) const { return map.count(k) > 0; }
    [[noreturn]] void bad(const std::string& k, const std::string& expected) const {
        throw Error("option '" + k + "': expected " + expected + ", got '" + map.at(k) + "'");
    }
    int integer(const std::string& k, int def, int lo, int hi) const {
        if (!has(k)) return def;
        const std::string& s = map.at(k);
        int v = 0;
        auto r = std::from_chars(s.data(), s.data() + s.size(), v);
        if (r.ec != std::errc() || r.ptr != s.data() + s.size() || v < lo || v > hi)
            bad(k, "an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
        return v;
    }
    bool flag(const std::string& k) const {
        if (!has(k)) return false;
        const std::string& s = map.at(k);
        if (s == "true" || s == "1" || s == "yes") return true;
        if (s == "false" || s == "0" || s == "no") return false;
        bad(k, "true or false");
    }
    float number(const std::string& k, float def) const {
        if (!has(k)) return def;
        try {
            size_t used = 0;
            float v = std::stof(map.at(k), &used);
            if (used == map.at(k).size() && std::isfinite(v)) return v;
        } catch (...) {
        }
        bad(k, "a number");
    }
    std::pair<float, float> range(float lo, float hi) const {
        if (!has("range")) return {lo, hi};
        const std::string& s = map.at("range");
        auto comma = s.find(',');
        try {
            if (comma != std::string::npos) {
                float a = std::stof(s.substr(0, comma)), b = std::stof(s.substr(comma + 1));
                if (b > a) return {a, b};
            }
        } catch (...) {
        }
        bad("range", "'lo,hi' with hi > lo");
    }
    std::vector<std::string> list(const std::string& k) const {
        std::vector<std::string> v;
        if (!has(k)) return v;
        std::stringstream ss(map.at(k));
        for (std::string item; std::getline(ss, item, ',');) {
            item.erase(0, item.find_first_not_of(' '));
            item.erase(item.find_last_not_of(' ') + 1);
            if (!item.empty()) v.push_back(item);
        }
        if (v.empty()) bad(k, "a comma-separated list of names");
        return v;
    }
};

template <typename F>
std::shared_ptr<F> select_channels(const F& f, const std::vector<std::string>& names) {
    if (names.empty()) return nullptr;
    std::vector<int> idx;
    for (const auto& n : names) {
        int c = f.find_channel(n);
        if (c < 0) {
            std::string have;
            for (const auto& h : f.channel_names()) have += (have.empty() ? "" : ", ") + h;
            throw Error("option 'channels': no channel '" + n + "' (the value has: " + have + ")");
        }
        idx.push_back(c);
    }
    auto out = std::make_shared<F>(f.resolution(), int(idx.size()), f.bounds(), names);
    for (size_t i = 0; i < idx.size(); ++i) std::copy(f.channel(idx[i]).begin(), f.channel(idx[i]).end(), out->channel(int(i)).begin());
    return out;
}

// The value, with the `channels` option applied.
Value selected(const Value& v, const Options& o) {
    auto names = o.list("channels");
    if (names.empty()) return v;
    if (auto f2 = std::get_if<Field2DPtr>(&v)) return Field2DPtr(select_channels(**f2, names));
    if (auto f3 = std::get_if<Field3DPtr>(&v)) return Field3DPtr(select_channels(**f3, names));
    return v;
}

// A 2D picture of a value: the field itself, one z slice, or a montage of all slices.
Field2D picture(const Value& v, const Options& o) {
    if (auto f2 = std::get_if<Field2DPtr>(&v)) {
        if (o.has("slice") || o.has("montage")) throw Error("options 'slice' and 'montage' apply to 3D fields only");
        return **f2;
    }
    const Field3D& f = *std::get<Field3DPtr>(v);
    const Box2d b2{{{f.bounds().min[0], f.bounds().min[1]}}, {{f.bounds().max[0], f.bounds().max[1]}}};
    if (o.flag("montage")) {
        const int cols = int(std::ceil(std::sqrt(double(f.nz()))));
        const int rows = (f.nz() + cols - 1) / cols;
        Field2D out({{f.nx() * cols, f.ny() * rows}}, f.channels(), Box2d{{{0, 0}}, {{double(f.nx() * cols), double(f.ny() * rows)}}},
                    f.channel_names());
        // Slice 0 at the top left, reading order left to right, top to bottom.
        for (int z = 0; z < f.nz(); ++z) {
            const int ox = (z % cols) * f.nx(), oy = (rows - 1 - z / cols) * f.ny();
            for (int c = 0; c < f.channels(); ++c)
                for (int y = 0; y < f.ny(); ++y)
                    for (int x = 0; x < f.nx(); ++x) out.at(c, ox + x, oy + y) = f.at(c, x, y, z);
        }
        return out;
    }
    const int z = o.integer("slice", f.nz() / 2, 0, f.nz() - 1);
    Field2D out({{f.nx(), f.ny()}}, f.channels(), b2, f.channel_names());
    for (int c = 0; c < f.channels(); ++c)
        std::copy_n(f.channel(c).data() + f.index(0, 0, z), f.voxel_count() / size_t(f.nz()), out.channel(c).data());
    return out;
}

std::vector<fs::path> write_exr_value(const Value& v, const fs::path& p, const OutputOptions& opts) {
    Options o{opts, p};
    ExrOptions eo;
    eo.half = o.flag("half");
    Value s = selected(v, o);
    if (auto f2 = std::get_if<Field2DPtr>(&s)) write_exr(**f2, p, eo);
    else write_exr(*std::get<Field3DPtr>(s), p, eo);
    return {p};
}

std::vector<fs::path> write_image_value(const Value& v, const fs::path& p, const OutputOptions& opts) {
    Options o{opts, p};
    ImageOptions io;
    io.bits = o.integer("bits", 8, 8, 16);
    if (io.bits != 8 && io.bits != 16) o.bad("bits", "8 or 16");
    std::tie(io.range_min, io.range_max) = o.range(0.0f, 1.0f);
    write_image(picture(selected(v, o), o), p, io);
    return {p};
}

std::vector<fs::path> write_vdb_value(const Value& v, const fs::path& p, const OutputOptions& opts) {
    Options o{opts, p};
    VdbOptions vo;
    vo.tolerance = o.number("tolerance", 0.0f);
    if (vo.tolerance < 0) o.bad("tolerance", "a number >= 0");
    vo.vector3 = o.flag("vector3");
    write_vdb(*std::get<Field3DPtr>(selected(v, o)), p, vo);
    return {p};
}

std::vector<fs::path> write_slices_value(const Value& v, const fs::path& p, const OutputOptions& opts) {
    Options o{opts, p};
    SliceOptions so;
    std::tie(so.range_min, so.range_max) = o.range(0.0f, 1.0f);
    so.default_alpha = uint8_t(o.integer("alpha", 255, 0, 255));
    return write_tga_slices(*std::get<Field3DPtr>(selected(v, o)), p.parent_path(), p.filename().string(), so);
}

struct Entry {
    OutputFormat format;
    Writer write;
};

const std::vector<Entry>& entries() {
    static const std::vector<Entry> table = {
        {{"exr", {".exr"}, {PortType::Field2D, PortType::Field3D},
          "OpenEXR, 32-bit float (or half); 3D fields as stacked slices with Atlas header attributes",
          {{"half", "store 16-bit half floats (true/false)"}, {"channels", "comma-separated channels to write, in order"}}},
         write_exr_value},
        {{"png", {".png"}, {PortType::Field2D, PortType::Field3D},
          "PNG, 8 or 16 bits per channel, 1-4 channels; a 3D field writes one slice or a montage",
          {{"bits", "8 or 16"}, {"range", "'lo,hi': values mapped to 0 and full scale (default 0,1)"},
           {"slice", "z index of a 3D field's slice (default: the middle)"}, {"montage", "true: all slices tiled in one image"},
           {"channels", "comma-separated channels to write, in order"}}},
         write_image_value},
        {{"tga", {".tga"}, {PortType::Field2D, PortType::Field3D}, "TGA, 8 bits per channel, uncompressed",
          {{"range", "'lo,hi': values mapped to 0 and 255 (default 0,1)"}, {"slice", "z index of a 3D field's slice"},
           {"montage", "true: all slices tiled in one image"}, {"channels", "comma-separated channels to write, in order"},
           {"bits", "8 (TGA holds 8 bits)"}}},
         write_image_value},
        {{"vdb", {".vdb"}, {PortType::Field3D}, "OpenVDB, one float grid per channel named after it (fog volumes)",
          {{"tolerance", "values within this of 0 stay inactive (default 0)"}, {"vector3", "true: 3 channels as one vec3s grid"},
           {"channels", "comma-separated channels to write, in order"}}},
         write_vdb_value},
        {{"tga-slices", {}, {PortType::Field3D},
          "a stack of 32-bit TGA slices FILE.001.tga ... (the Nubis voxel cloud pack layout), RGBA from the first 4 channels",
          {{"range", "'lo,hi': values mapped to 0 and 255 (default 0,1)"}, {"alpha", "alpha value 0..255 when the field has < 4 channels"},
           {"channels", "comma-separated channels for R, G, B, A"}}},
         write_slices_value},
    };
    return table;
}

} // namespace

const std::vector<OutputFormat>& output_formats() {
    static const std::vector<OutputFormat> formats = [] {
        std::vector<OutputFormat> v;
        for (const auto& e : entries()) v.push_back(e.format);
        return v;
    }();
    return formats;
}

std::string output_format_for_path(const fs::path& path) {
    std::string ext = path.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    std::string known;
    for (const auto& e : entries())
        for (const auto& x : e.format.extensions) {
            if (x == ext) return e.format.name;
            known += (known.empty() ? "" : ", ") + x;
        }
    throw Error("cannot tell the format from the extension '" + ext + "' (known: " + known +
                "); add 'format:' (e.g. format: tga-slices)");
}

std::vector<fs::path> write_value(const Value& value, const fs::path& path, const std::string& format, const OutputOptions& options) {
    for (const auto& e : entries()) {
        if (e.format.name != format) continue;
        const PortType t = value_type(value);
        if (std::find(e.format.accepts.begin(), e.format.accepts.end(), t) == e.format.accepts.end())
            throw Error("format '" + format + "' cannot write a " + std::string(port_type_name(t)));
        for (const auto& kv : options) {
            bool known = false;
            for (const auto& o : e.format.options) known = known || o.first == kv.first;
            if (!known) {
                std::string list;
                for (const auto& o : e.format.options) list += (list.empty() ? "" : ", ") + o.first;
                throw Error("unknown option '" + kv.first + "' for format '" + format + "' (known: " + list + ")");
            }
        }
        return e.write(value, path, options);
    }
    throw Error("unknown output format '" + format + "'");
}

} // namespace atlas::io

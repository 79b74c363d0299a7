// The writer behind each output format: parse options, shape the value, write.
#include "atlas/core/error.h"
#include "atlas/io/exr.h"
#include "atlas/io/image.h"
#include "atlas/io/output_options.h"
#include "atlas/io/tga_slices.h"
#include "atlas/io/vdb.h"
#include "format_table.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace atlas::io::detail {

namespace {

template <typename F>
std::shared_ptr<const F> select_channels(const std::shared_ptr<const F>& f, const std::vector<std::string>& names, const OptionReader& o) {
    if (names.empty()) return f;
    if (names.size() > 64) o.bad("channels", "at most 64 names");
    std::vector<int> idx;
    for (const auto& n : names) {
        const int c = f->find_channel(n);
        if (c < 0) {
            std::string have;
            for (const auto& h : f->channel_names()) have += (have.empty() ? "" : ", ") + h;
            throw Error(o.prefix() + "option 'channels': no channel '" + n + "' (the value has: " + have + ")");
        }
        idx.push_back(c);
    }
    auto out = std::make_shared<F>(f->resolution(), int(idx.size()), f->bounds(), names);
    for (size_t i = 0; i < idx.size(); ++i) std::copy(f->channel(idx[i]).begin(), f->channel(idx[i]).end(), out->channel(int(i)).begin());
    return out;
}

// The value with the `channels` option applied (a field of either dimension).
Value selected(const Value& v, const OptionReader& o) {
    const auto names = o.list("channels");
    if (auto f2 = std::get_if<Field2DPtr>(&v)) return Field2DPtr(select_channels(*f2, names, o));
    return Field3DPtr(select_channels(std::get<Field3DPtr>(v), names, o));
}

// Every slice tiled in a ceil(sqrt(nz))-column grid, slice 0 at the top left,
// reading order left to right then downwards; unused tiles are 0. Bounds are
// texel units (the montage is a picture, not a place).
Field2D montage(const Field3D& f) {
    const int cols = int(std::ceil(std::sqrt(double(f.nz()))));
    const int rows = (f.nz() + cols - 1) / cols;
    const int64_t w = int64_t(f.nx()) * cols, h = int64_t(f.ny()) * rows;
    if (w > (1 << 30) || h > (1 << 30)) throw Error("the montage would be " + std::to_string(w) + "x" + std::to_string(h) + " pixels");
    Field2D out({{int(w), int(h)}}, f.channels(), Box2d{{{0, 0}}, {{double(w), double(h)}}}, f.channel_names());
    for (int z = 0; z < f.nz(); ++z) {
        // Image y is up, so the first tile row is the highest field rows.
        const int ox = (z % cols) * f.nx(), oy = (rows - 1 - z / cols) * f.ny();
        for (int c = 0; c < f.channels(); ++c)
            for (int y = 0; y < f.ny(); ++y) std::copy_n(f.channel(c).data() + f.index(0, y, z), size_t(f.nx()), out.channel(c).data() + out.index(ox, oy + y));
    }
    return out;
}

// A 2D picture of a value: the field itself, one z slice, or a montage.
Field2DPtr picture(const Value& v, const OptionReader& o) {
    if (auto f2 = std::get_if<Field2DPtr>(&v)) {
        if (o.has("slice")) o.bad("slice", "no slice option for a 2D field");
        if (o.has("montage")) o.bad("montage", "no montage option for a 2D field");
        return *f2;
    }
    const Field3D& f = *std::get<Field3DPtr>(v);
    if (o.flag("montage")) {
        if (o.has("slice")) throw Error(o.prefix() + "options 'montage' and 'slice' exclude each other");
        return std::make_shared<Field2D>(montage(f));
    }
    const int z = o.integer("slice", f.nz() / 2, 0, f.nz() - 1);
    const Box2d b2{{{f.bounds().min[0], f.bounds().min[1]}}, {{f.bounds().max[0], f.bounds().max[1]}}};
    auto out = std::make_shared<Field2D>(Vec2i{{f.nx(), f.ny()}}, f.channels(), b2, f.channel_names());
    const size_t n = size_t(f.nx()) * size_t(f.ny());
    for (int c = 0; c < f.channels(); ++c) std::copy_n(f.channel(c).data() + f.index(0, 0, z), n, out->channel(c).data());
    return out;
}

std::string lower_extension(const fs::path& p) {
    std::string ext = p.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    return ext;
}

} // namespace

namespace {
ExrOptions exr_options(const OptionReader& o) {
    ExrOptions eo;
    eo.half = o.flag("half");
    if (o.has("meaning")) eo.channel_meaning = o.text("meaning");
    if (o.has("compression")) {
        const std::string& c = o.text("compression");
        if (c == "zip") eo.compress = true;
        else if (c == "none") eo.compress = false;
        else o.bad("compression", "zip or none");
    }
    o.list("channels");
    return eo;
}
} // namespace

void check_exr_options(const OptionReader& o, const fs::path&, PortType) { exr_options(o); }

std::vector<fs::path> write_exr_output(const Value& v, const fs::path& p, const OutputOptions& opts, OutputMetrics&) {
    const OptionReader o(opts, p);
    const ExrOptions eo = exr_options(o);
    const Value s = selected(v, o);
    if (auto f2 = std::get_if<Field2DPtr>(&s)) write_exr(**f2, p, eo);
    else write_exr(*std::get<Field3DPtr>(s), p, eo);
    return {p};
}

namespace {
// The options of png/tga that do not depend on the value (checked when the graph loads too).
ImageOptions image_options(const OptionReader& o, const fs::path& p) {
    const bool tga = lower_extension(p) == ".tga";
    ImageOptions io;
    io.bits = o.integer("bits", 8, 0, 64);
    if (tga ? io.bits != 8 : (io.bits != 8 && io.bits != 16)) o.bad("bits", tga ? "8 (TGA holds 8 bits per channel)" : "8 or 16");
    std::tie(io.range_min, io.range_max) = o.range("range", 0.0f, 1.0f);
    o.list("channels");
    if (o.has("slice")) o.integer("slice", 0, 0, std::numeric_limits<int>::max());
    if (o.flag("montage") && o.has("slice")) throw Error(o.prefix() + "options 'montage' and 'slice' exclude each other");
    return io;
}
} // namespace

void check_image_options(const OptionReader& o, const fs::path& p, PortType produced) {
    image_options(o, p);
    if (produced == PortType::Field2D) {
        if (o.has("slice")) o.bad("slice", "no slice option for a 2D field");
        if (o.has("montage")) o.bad("montage", "no montage option for a 2D field");
    }
}

std::vector<fs::path> write_image_output(const Value& v, const fs::path& p, const OutputOptions& opts, OutputMetrics&) {
    const OptionReader o(opts, p);
    const bool tga = lower_extension(p) == ".tga";
    const ImageOptions io = image_options(o, p);
    const Value s = selected(v, o);
    const int channels = std::holds_alternative<Field2DPtr>(s) ? std::get<Field2DPtr>(s)->channels() : std::get<Field3DPtr>(s)->channels();
    if (channels > 4 || (tga && channels == 2))
        throw Error(o.prefix() + (tga ? "a TGA holds 1, 3 or 4 channels" : "an image holds 1 to 4 channels") + ", the value has " +
                    std::to_string(channels) + "; choose some with option 'channels'");
    write_image(*picture(s, o), p, io);
    return {p};
}

namespace {
VdbOptions vdb_options(const OptionReader& o) {
    VdbOptions vo;
    vo.tolerance = o.number("tolerance", 0.0f, 0.0f, std::numeric_limits<float>::infinity());
    vo.vector3 = o.flag("vector3");
    vo.grid_names = o.list("grids");
    o.list("channels");
    return vo;
}
} // namespace

void check_vdb_options(const OptionReader& o, const fs::path&, PortType) { vdb_options(o); }

std::vector<fs::path> write_vdb_output(const Value& v, const fs::path& p, const OutputOptions& opts, OutputMetrics&) {
    const OptionReader o(opts, p);
    const VdbOptions vo = vdb_options(o);
    write_vdb(*std::get<Field3DPtr>(selected(v, o)), p, vo);
    return {p};
}

namespace {
// Every option of a slice stack except the channel names' existence; `holds`: channels per pixel.
SliceOptions slice_options(const OptionReader& o, const fs::path& p, int& holds) {
    if (lower_extension(p) == ".tga")
        throw Error(o.prefix() + "format 'tga-slices' takes DIR/STEM (it writes STEM.001.tga, STEM.002.tga, ... or STEM(0).tga, ...), not a .tga file name");
    SliceOptions so;
    std::tie(so.range_min, so.range_max) = o.range("range", 0.0f, 1.0f);
    so.default_alpha = uint8_t(o.integer("alpha", 255, 0, 255));
    if (o.has("naming")) {
        const std::string& n = o.text("naming");
        if (n == "atlas") so.naming = SliceNaming::atlas;
        else if (n == "nubis") so.naming = SliceNaming::nubis;
        else o.bad("naming", "atlas (STEM.001.tga ...) or nubis (STEM(0).tga ...)");
    }
    if (o.has("compression")) {
        const std::string& c = o.text("compression");
        if (c == "rle") so.rle = true;
        else if (c == "none") so.rle = false;
        else o.bad("compression", "rle or none");
    }
    holds = 4;
    if (o.has("pixels")) {
        const std::string& px = o.text("pixels");
        if (px == "rgba") so.pixels = SlicePixels::rgba;
        else if (px == "rgb") so.pixels = SlicePixels::rgb, holds = 3;
        else if (px == "gray") so.pixels = SlicePixels::gray, holds = 1;
        else o.bad("pixels", "rgba (32-bit), rgb (24-bit) or gray (8-bit)");
    }
    if (holds < 4 && o.has("alpha")) throw Error(o.prefix() + "option 'alpha' needs pixels 'rgba' (these slices have no alpha)");
    const std::string kind = holds == 4 ? "RGBA" : (holds == 3 ? "RGB" : "gray");
    if (int(o.list("channels").size()) > holds)
        o.bad("channels", "at most " + std::to_string(holds) + (holds == 1 ? " name (" : " names (") + kind + ")");
    return so;
}
} // namespace

void check_tga_slices_options(const OptionReader& o, const fs::path& p, PortType) {
    int holds = 4;
    slice_options(o, p, holds);
}

std::vector<fs::path> write_tga_slices_output(const Value& v, const fs::path& p, const OutputOptions& opts, OutputMetrics&) {
    const OptionReader o(opts, p);
    int holds = 4;
    SliceOptions so = slice_options(o, p, holds);
    const std::string kind = holds == 4 ? "RGBA" : (holds == 3 ? "RGB" : "gray");
    const Field3DPtr f = std::get<Field3DPtr>(selected(v, o));
    for (int k = 0; k < 4; ++k) so.channel_map.push_back(k < f->channels() && k < holds ? k : -1);
    if (f->channels() > holds && !o.has("channels"))
        throw Error(o.prefix() + "a" + (holds == 4 ? "n " : " ") + kind + " TGA slice holds " + std::to_string(holds) + " channel" +
                    (holds == 1 ? "" : "s") + ", the value has " + std::to_string(f->channels()) + "; choose them with option 'channels'");
    return write_tga_slices(*f, p.parent_path(), p.filename().string(), so);
}

} // namespace atlas::io::detail

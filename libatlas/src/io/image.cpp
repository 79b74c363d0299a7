// 8/16-bit images through OpenImageIO (see image.h for orientation and mapping).
#include "atlas/io/image.h"

#include "atlas/core/error.h"
#include "atlas/core/files.h"
#include "io_common.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <cctype>
#include <cmath>
#include <vector>

namespace atlas::io {

namespace {

std::string lower_extension(const fs::path& path) {
    std::string ext = path.extension().string();
    for (auto& ch : ext) ch = char(std::tolower(static_cast<unsigned char>(ch)));
    return ext;
}

std::string texel_name(int x, int y) { return "(" + std::to_string(x) + ", " + std::to_string(y) + ")"; }

} // namespace

void write_image(const Field2D& f, const fs::path& path, const ImageOptions& o) {
    const std::string ext = lower_extension(path);
    const std::string where = path.string() + ": cannot write image: ";
    if (f.channels() > 4) throw Error(where + "an image holds 1 to 4 channels, the field has " + std::to_string(f.channels()));
    if (o.bits != 8 && o.bits != 16) throw Error(where + "bits must be 8 or 16, got " + std::to_string(o.bits));
    if (o.bits == 16 && ext == ".tga") throw Error(where + "TGA holds 8 bits per channel, not 16; use PNG for 16 bits");
    if (ext == ".tga" && f.channels() == 2) throw Error(where + "TGA holds 1, 3 or 4 channels, the field has 2; use PNG");
    if (!detail::valid_range(o.range_min, o.range_max))
        throw Error(where + "range must be finite with max > min, got [" + std::to_string(o.range_min) + ", " + std::to_string(o.range_max) + "]");
    const int w = f.width(), h = f.height(), nc = f.channels();
    const detail::Quantiser quantise(o.range_min, o.range_max, o.bits);
    // Interleaved, file row order: field row y is file row h-1-y.
    std::vector<uint16_t> q(size_t(w) * size_t(h) * size_t(nc));
    for (int c = 0; c < nc; ++c)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                const float v = f.at(c, x, y);
                if (std::isnan(v)) throw Error(where + "NaN at texel " + texel_name(x, y) + " of channel '" + f.channel_name(c) + "'");
                q[(size_t(h - 1 - y) * size_t(w) + size_t(x)) * size_t(nc) + size_t(c)] = quantise(v);
            }
    // Encoded in memory, then written with every write checked: OpenImageIO's
    // PNG writer does not report a short write (a full disk gave a truncated
    // file and success).
    std::vector<unsigned char> encoded;
    OIIO::Filesystem::IOVecOutput proxy(encoded);
    auto out = OIIO::ImageOutput::create(path.string());
    if (!out) throw Error(where + "no image writer for the extension '" + ext + "' (" + OIIO::geterror() + ")");
    if (!out->supports("ioproxy") || !out->set_ioproxy(&proxy)) throw Error(where + "the image writer cannot encode in memory");
    const OIIO::TypeDesc type = o.bits == 8 ? OIIO::TypeDesc::UINT8 : OIIO::TypeDesc::UINT16;
    OIIO::ImageSpec spec(w, h, nc, type);
    if (ext == ".tga") spec.attribute("compression", "none"); // plain 8-bit TGA, as game pipelines expect
    // Channels are independent data, never colour premultiplied by alpha.
    spec.attribute("oiio:UnassociatedAlpha", 1);
    if (!out->open(path.string(), spec)) throw Error(where + out->geterror());
    bool ok;
    if (o.bits == 8) {
        std::vector<uint8_t> b(q.begin(), q.end());
        ok = out->write_image(OIIO::TypeDesc::UINT8, b.data());
    } else {
        ok = out->write_image(OIIO::TypeDesc::UINT16, q.data());
    }
    ok = out->close() && ok;
    if (!ok) throw Error(where + out->geterror());
    try {
        write_file_checked(path, encoded.data(), encoded.size());
    } catch (const Error& e) {
        std::error_code ec;
        fs::remove(path, ec);
        throw Error(where + e.what());
    }
}

Field2D read_image(const fs::path& path, std::optional<Box2d> bounds, const MemoryBudget* budget) {
    detail::require_regular_file(path, "image");
    const std::string where = path.string() + ": cannot read image: ";
    if (bounds && !bounds->valid()) throw Error(where + "bounds must be finite with max > min in both axes");
    const MemoryBudget fallback;
    const MemoryBudget& bud = detail::budget_or_default(budget, fallback);
    // Keep alpha as stored: no premultiplication on read.
    OIIO::ImageSpec config;
    config.attribute("oiio:UnassociatedAlpha", 1);
    auto in = OIIO::ImageInput::open(path.string(), &config);
    if (!in) throw Error(where + OIIO::geterror());
    const OIIO::ImageSpec spec = in->spec();
    const int64_t w = spec.width, h = spec.height, nc = spec.nchannels;
    if (w <= 0 || h <= 0 || nc <= 0) throw Error(where + "the image has no pixels");
    if (w > (1 << 30) || h > (1 << 30)) throw Error(where + "the image claims an absurd size " + std::to_string(w) + "x" + std::to_string(h));
    if (nc > 64) throw Error(where + "the image has " + std::to_string(nc) + " channels; at most 64 are supported");
    if (spec.depth > 1) throw Error(where + "volume images are not supported here; use a TGA slice stack, EXR or VDB");
    try {
        bud.check(field_bytes(uint64_t(w) * uint64_t(h), int(nc)) * 2, "a " + std::to_string(w) + "x" + std::to_string(h) + "x" + std::to_string(nc) + " image");
    } catch (const MemoryBudgetError& e) {
        throw MemoryBudgetError(path.string() + ": " + e.what());
    }
    std::vector<float> px(size_t(w) * size_t(h) * size_t(nc));
    // Integer formats convert to 0..1 (value / (2^bits - 1)); float formats pass through.
    if (!in->read_image(0, 0, 0, int(nc), OIIO::TypeDesc::FLOAT, px.data())) throw Error(where + in->geterror());
    in->close();
    std::vector<std::string> names;
    for (int c = 0; c < nc; ++c) {
        std::string n = c < int(spec.channelnames.size()) ? spec.channelnames[size_t(c)] : "";
        for (auto& ch : n) ch = char(std::tolower(static_cast<unsigned char>(ch)));
        names.push_back(n);
    }
    // Missing, empty or clashing names (rare) fall back to the defaults.
    bool usable = true;
    for (size_t i = 0; i < names.size(); ++i) {
        usable = usable && !names[i].empty();
        for (size_t j = i + 1; j < names.size(); ++j) usable = usable && names[i] != names[j];
    }
    if (!usable) names = default_channel_names(int(nc));
    const Box2d b = bounds ? *bounds : Box2d{{{0, 0}}, {{double(w), double(h)}}};
    Field2D f({{int(w), int(h)}}, int(nc), b, names, &bud);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int c = 0; c < nc; ++c) f.at(c, x, y) = px[(size_t(h - 1 - y) * size_t(w) + size_t(x)) * size_t(nc) + size_t(c)];
    return f;
}

} // namespace atlas::io

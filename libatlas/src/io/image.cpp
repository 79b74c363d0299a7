#include "atlas/io/image.h"

#include "atlas/core/error.h"

#include <OpenImageIO/imageio.h>

#include <cmath>
#include <vector>

namespace atlas::io {

void write_image(const Field2D& f, const fs::path& path, const ImageOptions& o) {
    std::string ext = path.extension().string();
    for (auto& ch : ext) ch = char(std::tolower(static_cast<unsigned char>(ch)));
    if (f.channels() > 4) throw Error(path.string() + ": an image holds 1 to 4 channels, the field has " + std::to_string(f.channels()));
    if (o.bits != 8 && o.bits != 16) throw Error(path.string() + ": bits must be 8 or 16, got " + std::to_string(o.bits));
    if (o.bits == 16 && ext == ".tga") throw Error(path.string() + ": TGA holds 8 bits per channel; use PNG for 16");
    if (!(o.range_max > o.range_min)) throw Error(path.string() + ": range max must be greater than range min");
    const int w = f.width(), h = f.height(), nc = f.channels();
    const double scale = (o.bits == 8 ? 255.0 : 65535.0) / (double(o.range_max) - double(o.range_min));
    const double top = o.bits == 8 ? 255.0 : 65535.0;
    std::vector<uint16_t> q(size_t(w) * size_t(h) * size_t(nc));
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int c = 0; c < nc; ++c) {
                float v = f.at(c, x, y);
                if (std::isnan(v))
                    throw Error(path.string() + ": NaN at texel (" + std::to_string(x) + ", " + std::to_string(y) + ") of channel '" +
                                f.channel_name(c) + "'");
                double s = std::clamp((double(v) - o.range_min) * scale, 0.0, top);
                q[(size_t(h - 1 - y) * size_t(w) + size_t(x)) * size_t(nc) + size_t(c)] = uint16_t(std::lround(s));
            }
    auto out = OIIO::ImageOutput::create(path.string());
    if (!out) throw Error(path.string() + ": no image writer for '" + ext + "': " + OIIO::geterror());
    OIIO::TypeDesc type = o.bits == 8 ? OIIO::TypeDesc::UINT8 : OIIO::TypeDesc::UINT16;
    OIIO::ImageSpec spec(w, h, nc, type);
    spec.attribute("compression", ext == ".tga" ? "none" : "zip");
    spec.attribute("oiio:UnassociatedAlpha", 1);
    if (!out->open(path.string(), spec)) throw Error(path.string() + ": cannot write image: " + out->geterror());
    bool ok;
    if (o.bits == 8) {
        std::vector<uint8_t> b(q.begin(), q.end());
        ok = out->write_image(OIIO::TypeDesc::UINT8, b.data());
    } else {
        ok = out->write_image(OIIO::TypeDesc::UINT16, q.data());
    }
    if (!ok || !out->close()) throw Error(path.string() + ": cannot write image: " + out->geterror());
}

Field2D read_image(const fs::path& path, std::optional<Box2d> bounds, const MemoryBudget* budget) {
    if (!fs::exists(path)) throw Error(path.string() + ": cannot open image (no such file)");
    auto in = OIIO::ImageInput::open(path.string());
    if (!in) throw Error(path.string() + ": cannot read image: " + OIIO::geterror());
    const OIIO::ImageSpec& spec = in->spec();
    const int w = spec.width, h = spec.height, nc = spec.nchannels;
    if (w <= 0 || h <= 0 || nc <= 0) throw Error(path.string() + ": image has no pixels");
    if (nc > 64) throw Error(path.string() + ": image has " + std::to_string(nc) + " channels (at most 64 are supported)");
    if (spec.depth > 1) throw Error(path.string() + ": volume images are not supported here; use a TGA slice stack or VDB");
    Box2d b = bounds ? *bounds : Box2d{{{0, 0}}, {{double(w), double(h)}}};
    if (budget) budget->check(uint64_t(w) * uint64_t(h) * uint64_t(nc) * 8, path.string() + ": reading the image");
    std::vector<float> px(size_t(w) * size_t(h) * size_t(nc));
    if (!in->read_image(0, 0, 0, nc, OIIO::TypeDesc::FLOAT, px.data())) throw Error(path.string() + ": cannot read image: " + in->geterror());
    in->close();
    std::vector<std::string> names;
    for (int c = 0; c < nc; ++c) {
        std::string n = c < int(spec.channelnames.size()) ? spec.channelnames[size_t(c)] : "";
        for (auto& ch : n) ch = char(std::tolower(static_cast<unsigned char>(ch)));
        names.push_back(n.empty() ? "c" + std::to_string(c) : n);
    }
    // Duplicate or clashing names (rare) fall back to defaults.
    for (size_t i = 0; i < names.size(); ++i)
        for (size_t j = i + 1; j < names.size(); ++j)
            if (names[i] == names[j]) names = default_channel_names(nc);
    Field2D f({{w, h}}, nc, b, names, budget);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int c = 0; c < nc; ++c) f.at(c, x, y) = px[(size_t(h - 1 - y) * size_t(w) + size_t(x)) * size_t(nc) + size_t(c)];
    return f;
}

} // namespace atlas::io

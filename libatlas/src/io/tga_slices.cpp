#include "atlas/io/tga_slices.h"

#include "atlas/core/error.h"
#include "atlas/io/image.h"

#include <OpenImageIO/imageio.h>

#include <cmath>

namespace atlas::io {

namespace {
std::string slice_name(const std::string& stem, int index, int digits) {
    std::string n = std::to_string(index);
    if (int(n.size()) < digits) n = std::string(size_t(digits - int(n.size())), '0') + n;
    return stem + "." + n + ".tga";
}
} // namespace

std::vector<fs::path> write_tga_slices(const Field3D& f, const fs::path& dir, const std::string& stem, const SliceOptions& o) {
    if (stem.empty()) throw Error("tga-slices: empty file stem");
    if (!(o.range_max > o.range_min)) throw Error("tga-slices: range max must be greater than range min");
    std::vector<int> map = o.channel_map;
    if (map.empty())
        for (int c = 0; c < 4; ++c) map.push_back(c < f.channels() ? c : -1);
    if (map.size() != 4) throw Error("tga-slices: the channel map needs 4 entries (R, G, B, A)");
    for (int m : map)
        if (m >= f.channels()) throw Error("tga-slices: channel map refers to channel " + std::to_string(m) + " of a " +
                                           std::to_string(f.channels()) + "-channel field");
    const int digits = std::max(3, int(std::to_string(f.nz()).size()));
    const int w = f.nx(), h = f.ny();
    const double scale = 255.0 / (double(o.range_max) - double(o.range_min));
    std::vector<fs::path> written;
    std::vector<uint8_t> px(size_t(w) * size_t(h) * 4);
    for (int z = 0; z < f.nz(); ++z) {
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x)
                for (int k = 0; k < 4; ++k) {
                    uint8_t v;
                    if (map[size_t(k)] < 0) {
                        v = k == 3 ? o.default_alpha : 0;
                    } else {
                        float s = f.at(map[size_t(k)], x, y, z);
                        if (std::isnan(s))
                            throw Error("tga-slices: NaN at voxel (" + std::to_string(x) + ", " + std::to_string(y) + ", " + std::to_string(z) + ")");
                        v = uint8_t(std::lround(std::clamp((double(s) - o.range_min) * scale, 0.0, 255.0)));
                    }
                    px[(size_t(h - 1 - y) * size_t(w) + size_t(x)) * 4 + size_t(k)] = v;
                }
        fs::path p = dir / slice_name(stem, z + 1, digits);
        auto out = OIIO::ImageOutput::create(p.string());
        if (!out) throw Error(p.string() + ": no TGA writer: " + OIIO::geterror());
        OIIO::ImageSpec spec(w, h, 4, OIIO::TypeDesc::UINT8);
        spec.attribute("compression", "none");
        spec.attribute("oiio:UnassociatedAlpha", 1);
        if (!out->open(p.string(), spec) || !out->write_image(OIIO::TypeDesc::UINT8, px.data()) || !out->close())
            throw Error(p.string() + ": cannot write TGA slice: " + out->geterror());
        written.push_back(p);
    }
    return written;
}

std::vector<fs::path> find_tga_slices(const fs::path& first) {
    // STEM.<digits ending in 1, otherwise zeros>.tga, e.g. clouds.001.tga
    const std::string name = first.filename().string();
    std::string lower = name;
    for (auto& ch : lower) ch = char(std::tolower(static_cast<unsigned char>(ch)));
    const auto bad_name = [&] { return Error(first.string() + ": expected the first slice of a stack, named STEM.001.tga"); };
    if (lower.size() < 6 || lower.compare(lower.size() - 4, 4, ".tga") != 0) throw bad_name();
    const std::string base = name.substr(0, name.size() - 4);
    const auto dot = base.rfind('.');
    if (dot == std::string::npos || dot == 0) throw bad_name();
    const std::string number = base.substr(dot + 1);
    if (number.empty() || number.back() != '1' || number.find_first_not_of('0') != number.size() - 1) throw bad_name();
    const std::string stem = base.substr(0, dot);
    const int digits = int(number.size());
    std::vector<fs::path> files;
    for (int i = 1;; ++i) {
        fs::path p = first.parent_path() / slice_name(stem, i, digits);
        if (!fs::exists(p)) break;
        files.push_back(p);
    }
    if (files.empty()) throw Error(first.string() + ": cannot open TGA slice (no such file)");
    // A gap followed by more slices is an error, not a short stack.
    fs::path after = first.parent_path() / slice_name(stem, int(files.size()) + 2, digits);
    if (fs::exists(after))
        throw Error((first.parent_path() / slice_name(stem, int(files.size()) + 1, digits)).string() + ": missing slice in the stack (" +
                    after.filename().string() + " exists)");
    return files;
}

Field3D read_tga_slices(const fs::path& first, Box3d bounds, int channels, const MemoryBudget* budget) {
    if (channels < 1 || channels > 4) throw Error("tga-slices: channels must be 1..4, got " + std::to_string(channels));
    const auto files = find_tga_slices(first);
    Field2D s0 = read_image(files[0]);
    const int w = s0.width(), h = s0.height();
    Field3D f({{w, h, int(files.size())}}, channels, bounds, {}, budget);
    for (size_t z = 0; z < files.size(); ++z) {
        Field2D s = z == 0 ? s0 : read_image(files[z]);
        if (s.width() != w || s.height() != h)
            throw Error(files[z].string() + ": slice is " + std::to_string(s.width()) + "x" + std::to_string(s.height()) + ", expected " +
                        std::to_string(w) + "x" + std::to_string(h) + " like the first slice");
        for (int c = 0; c < channels; ++c)
            for (int y = 0; y < h; ++y)
                for (int x = 0; x < w; ++x) f.at(c, x, y, int(z)) = c < s.channels() ? s.at(c, x, y) : (c == 3 ? 1.0f : 0.0f);
    }
    return f;
}

} // namespace atlas::io

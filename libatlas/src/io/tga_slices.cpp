// TGA slice stacks (the Nubis voxel cloud pack layout; see tga_slices.h).
#include "atlas/io/tga_slices.h"

#include "atlas/core/error.h"
#include "atlas/io/image.h"
#include "io_common.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <map>

namespace atlas::io {

namespace {

std::string slice_name(const std::string& stem, int index, int digits) {
    std::string n = std::to_string(index);
    if (int(n.size()) < digits) n = std::string(size_t(digits - int(n.size())), '0') + n;
    return stem + "." + n + ".tga";
}

bool iequals(const std::string& a, const std::string& b) {
    return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
               return std::tolower(static_cast<unsigned char>(x)) == std::tolower(static_cast<unsigned char>(y));
           });
}

bool all_digits(const std::string& s) {
    return !s.empty() && std::all_of(s.begin(), s.end(), [](char ch) { return ch >= '0' && ch <= '9'; });
}

// "STEM.<index part>.tga" -> {STEM, index part}; empty stem when the name has another shape.
std::pair<std::string, std::string> split_slice_name(const std::string& name) {
    if (name.size() < 4 || !iequals(name.substr(name.size() - 4), ".tga")) return {};
    const std::string base = name.substr(0, name.size() - 4);
    const size_t dot = base.rfind('.');
    if (dot == std::string::npos || dot == 0) return {};
    return {base.substr(0, dot), base.substr(dot + 1)};
}

// What a name given for the stack means: the stem, whether it names slice 1.
struct StackName {
    std::string stem;
    bool ok = false;
};

StackName parse_stack_name(const std::string& name) {
    auto [stem, index] = split_slice_name(name);
    if (!stem.empty()) {
        const bool hashes = !index.empty() && std::all_of(index.begin(), index.end(), [](char ch) { return ch == '#'; });
        const bool printf_style = index.size() >= 2 && index.front() == '%' && index.back() == 'd' &&
                                  (index.size() == 2 || all_digits(index.substr(1, index.size() - 2)));
        if (hashes || printf_style || index == "*") return {stem, true};
        if (all_digits(index)) return {stem, index.substr(std::min(index.find_first_not_of('0'), index.size())) == "1"};
        return {};
    }
    // A bare stem (DIR/STEM, as write_value takes it; it may contain dots).
    if (!name.empty() && !(name.size() >= 4 && iequals(name.substr(name.size() - 4), ".tga"))) return {name, true};
    return {};
}

} // namespace

std::vector<fs::path> write_tga_slices(const Field3D& f, const fs::path& dir, const std::string& stem, const SliceOptions& o) {
    if (stem.empty()) throw Error("tga-slices: the file stem is empty (expected DIR/STEM, giving STEM.001.tga ...)");
    const std::string where = "tga-slices '" + (dir / stem).string() + "': ";
    if (!detail::valid_range(o.range_min, o.range_max))
        throw Error(where + "range must be finite with max > min, got [" + std::to_string(o.range_min) + ", " + std::to_string(o.range_max) + "]");
    std::vector<int> map = o.channel_map;
    if (map.empty())
        for (int c = 0; c < 4; ++c) map.push_back(c < f.channels() ? c : -1);
    if (map.size() != 4) throw Error(where + "the channel map needs 4 entries (R, G, B, A), got " + std::to_string(map.size()));
    for (int m : map)
        if (m < -1 || m >= f.channels())
            throw Error(where + "the channel map refers to channel " + std::to_string(m) + " of a " + std::to_string(f.channels()) +
                        "-channel field (expected -1 or 0.." + std::to_string(f.channels() - 1) + ")");
    const int digits = std::max(3, int(std::to_string(f.nz()).size()));
    const int w = f.nx(), h = f.ny();
    const detail::Quantiser quantise(o.range_min, o.range_max, 8);
    std::vector<fs::path> written;
    std::vector<uint8_t> px(size_t(w) * size_t(h) * 4);
    for (int z = 0; z < f.nz(); ++z) {
        const fs::path p = dir / slice_name(stem, z + 1, digits);
        for (int k = 0; k < 4; ++k) {
            const int c = map[size_t(k)];
            for (int y = 0; y < h; ++y)
                for (int x = 0; x < w; ++x) {
                    uint8_t v = k == 3 ? o.default_alpha : 0;
                    if (c >= 0) {
                        const float s = f.at(c, x, y, z);
                        if (std::isnan(s))
                            throw Error(p.string() + ": cannot write TGA slice: NaN at voxel (" + std::to_string(x) + ", " + std::to_string(y) +
                                        ", " + std::to_string(z) + ") of channel '" + f.channel_name(c) + "'");
                        v = uint8_t(quantise(s));
                    }
                    // Field row y is image row h-1-y (bottom-up, as image.h).
                    px[(size_t(h - 1 - y) * size_t(w) + size_t(x)) * 4 + size_t(k)] = v;
                }
        }
        auto out = OIIO::ImageOutput::create(p.string());
        if (!out) throw Error(p.string() + ": cannot write TGA slice: no TGA writer (" + OIIO::geterror() + ")");
        OIIO::ImageSpec spec(w, h, 4, OIIO::TypeDesc::UINT8);
        spec.attribute("compression", "none");
        spec.attribute("oiio:UnassociatedAlpha", 1);
        bool ok = out->open(p.string(), spec) && out->write_image(OIIO::TypeDesc::UINT8, px.data());
        ok = out->close() && ok;
        if (!ok) throw Error(p.string() + ": cannot write TGA slice: " + out->geterror());
        written.push_back(p);
    }
    return written;
}

std::vector<fs::path> find_tga_slices(const fs::path& first) {
    const std::string name = first.filename().string();
    const StackName sn = parse_stack_name(name);
    if (!sn.ok)
        throw Error(first.string() + ": expected the first slice of a TGA stack (STEM.001.tga) or a pattern (STEM.###.tga, STEM.%03d.tga, "
                                     "STEM.*.tga, or DIR/STEM)");
    const fs::path dir = first.parent_path().empty() ? fs::path(".") : first.parent_path();
    // Every STEM.<digits>.tga in the directory, by index.
    std::map<long long, fs::path> found;
    std::error_code ec;
    for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
        const std::string n = it->path().filename().string();
        auto [stem, index] = split_slice_name(n);
        if (stem != sn.stem || !all_digits(index) || index.size() > 9) continue;
        const long long i = std::stoll(index);
        if (i < 1) continue;
        auto [pos, fresh] = found.emplace(i, first.parent_path() / n);
        if (!fresh) throw Error((first.parent_path() / n).string() + ": slice " + std::to_string(i) + " exists twice (also " +
                                pos->second.filename().string() + ")");
    }
    if (ec) throw Error(dir.string() + ": cannot list the directory of the TGA stack: " + ec.message());
    const int digits = 3;
    if (found.empty() || found.begin()->first != 1)
        throw Error((first.parent_path() / slice_name(sn.stem, 1, digits)).string() + ": cannot open TGA slice (no such file)");
    std::vector<fs::path> files;
    long long expect = 1;
    for (const auto& [i, p] : found) {
        if (i != expect) {
            const int width = std::max(digits, int(std::to_string(found.rbegin()->first).size()));
            throw Error((first.parent_path() / slice_name(sn.stem, int(expect), width)).string() + ": missing slice in the TGA stack (" +
                        p.filename().string() + " exists after it)");
        }
        files.push_back(p);
        ++expect;
    }
    return files;
}

Field3D read_tga_slices(const fs::path& first, Box3d bounds, int channels, const MemoryBudget* budget) {
    if (channels < 1 || channels > 4) throw Error(first.string() + ": tga-slices channels must be 1..4, got " + std::to_string(channels));
    if (!bounds.valid()) throw Error(first.string() + ": tga-slices bounds must be finite with max > min in every axis");
    const MemoryBudget fallback;
    const MemoryBudget& bud = detail::budget_or_default(budget, fallback);
    const auto files = find_tga_slices(first);
    Field2D s0 = read_image(files[0], std::nullopt, &bud);
    const int w = s0.width(), h = s0.height();
    Field3D f({{w, h, int(files.size())}}, channels, bounds, {}, &bud);
    for (size_t z = 0; z < files.size(); ++z) {
        const Field2D s = z == 0 ? std::move(s0) : read_image(files[z], std::nullopt, &bud);
        if (s.width() != w || s.height() != h)
            throw Error(files[z].string() + ": slice is " + std::to_string(s.width()) + "x" + std::to_string(s.height()) + ", expected " +
                        std::to_string(w) + "x" + std::to_string(h) + " like " + files[0].filename().string());
        // Channels the file lacks: colour 0, alpha 1 (opaque).
        for (int c = 0; c < channels; ++c)
            for (int y = 0; y < h; ++y)
                for (int x = 0; x < w; ++x) f.at(c, x, y, int(z)) = c < s.channels() ? s.at(c, x, y) : (c == 3 ? 1.0f : 0.0f);
    }
    return f;
}

} // namespace atlas::io

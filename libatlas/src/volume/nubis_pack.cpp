// The Nubis voxel cloud pack layouts, through the io module's TGA slice and VDB code.
#include "atlas/core/error.h"
#include "atlas/io/tga_slices.h"
#include "atlas/io/vdb.h"
#include "atlas/volume/nvdf.h"

#include <algorithm>
#include <fstream>
#include <iterator>

namespace atlas::volume {
namespace {
constexpr const char* kModelingNames[3] = {"dimensional_profile", "detail_type", "density_scale"};

// A 32-bit TGA slice (uncompressed or RLE) as RGBA bytes with row 0 at the
// bottom. Read here rather than through an image library because the pack's
// modeling slices carry A = 0, which premultiplying readers turn into black.
std::vector<uint8_t> read_tga_rgba(const std::filesystem::path& p, int& w, int& h) {
    std::ifstream in(p, std::ios::binary);
    if (!in) throw Error(p.string() + ": cannot open TGA slice");
    std::vector<uint8_t> b((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (b.size() < 18) throw Error(p.string() + ": not a TGA file (too short)");
    const int id_len = b[0], cmap = b[1], type = b[2];
    w = b[12] | (b[13] << 8);
    h = b[14] | (b[15] << 8);
    const int bpp = b[16], desc = b[17];
    if (cmap != 0 || (type != 2 && type != 10) || bpp != 32)
        throw Error(p.string() + ": expected a 32-bit true-colour TGA (the Nubis pack layout), got type " + std::to_string(type) + ", " +
                    std::to_string(bpp) + " bits");
    const size_t n = size_t(w) * size_t(h);
    std::vector<uint8_t> px(n * 4);
    size_t pos = 18 + size_t(id_len), i = 0;
    auto need = [&](size_t k) {
        if (pos + k > b.size()) throw Error(p.string() + ": TGA pixel data is truncated");
    };
    auto put = [&](size_t at, size_t src) { px[at * 4 + 0] = b[src + 2], px[at * 4 + 1] = b[src + 1], px[at * 4 + 2] = b[src], px[at * 4 + 3] = b[src + 3]; };
    while (i < n) {
        if (type == 2) { need(4); put(i++, pos); pos += 4; continue; }
        need(1);
        const int head = b[pos++];
        const size_t count = size_t(head & 0x7f) + 1;
        if (i + count > n) throw Error(p.string() + ": TGA run overflows the image");
        if (head & 0x80) { need(4); for (size_t k = 0; k < count; ++k) put(i++, pos); pos += 4; }
        else { need(4 * count); for (size_t k = 0; k < count; ++k, pos += 4) put(i++, pos); }
    }
    if (desc & 0x20) { // top-left origin: flip to bottom-up
        for (int y = 0; y < h / 2; ++y)
            std::swap_ranges(px.begin() + long(size_t(y) * size_t(w) * 4), px.begin() + long(size_t(y + 1) * size_t(w) * 4),
                             px.begin() + long(size_t(h - 1 - y) * size_t(w) * 4));
    }
    return px;
}

Field3D read_slices_rgba(const std::filesystem::path& first, Box3d bounds, int channels, std::vector<std::string> names,
                         const MemoryBudget* budget) {
    const std::vector<std::filesystem::path> files = io::find_tga_slices(first);
    int w = 0, h = 0;
    std::vector<uint8_t> px = read_tga_rgba(files[0], w, h);
    Field3D out({{w, h, int(files.size())}}, channels, bounds, std::move(names), budget);
    for (size_t z = 0; z < files.size(); ++z) {
        if (z > 0) {
            int w2 = 0, h2 = 0;
            px = read_tga_rgba(files[z], w2, h2);
            if (w2 != w || h2 != h) throw Error(files[z].string() + ": slice size differs from the first slice");
        }
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x)
                for (int c = 0; c < channels; ++c)
                    out.at(c, x, y, int(z)) = float(px[(size_t(y) * size_t(w) + size_t(x)) * 4 + size_t(c)]) / 255.0f;
    }
    return out;
}
} // namespace

std::vector<std::filesystem::path> write_nubis_modeling_tga(const Field3D& nvdf, const std::filesystem::path& dir, const std::string& stem) {
    if (nvdf.channels() != 3) throw Error("Nubis modeling TGA: expected a 3-channel NVDF, got " + std::to_string(nvdf.channels()) + " channels");
    io::SliceOptions o;
    o.channel_map = {0, 1, 2, -1};
    o.default_alpha = 0;
    return io::write_tga_slices(nvdf, dir, stem, o);
}

std::vector<std::filesystem::path> write_nubis_field_data_tga(const Field3D& sdf, const std::filesystem::path& dir, const std::string& stem) {
    io::SliceOptions o;
    o.range_min = float(kNubisSdfMin);
    o.range_max = float(kNubisSdfMax);
    o.channel_map = {0, -1, -1, -1};
    o.default_alpha = 255;
    return io::write_tga_slices(sdf, dir, stem, o);
}

Field3D read_nubis_modeling_tga(const std::filesystem::path& first, Box3d bounds, const MemoryBudget* budget) {
    return read_slices_rgba(first, bounds, 3, {kModelingNames[0], kModelingNames[1], kModelingNames[2]}, budget);
}

Field3D read_nubis_field_data_tga(const std::filesystem::path& first, Box3d bounds, const MemoryBudget* budget) {
    Field3D r = read_slices_rgba(first, bounds, 1, {"field_data"}, budget);
    return decode_field_data(r, kNubisSdfMin, kNubisSdfMax, 0, budget);
}

void write_nubis_vdb(const Field3D& nvdf, const Field3D& sdf, const std::filesystem::path& file) {
    if (nvdf.channels() != 3) throw Error("Nubis VDB: expected a 3-channel NVDF");
    if (sdf.resolution() != nvdf.resolution() || !(sdf.bounds() == nvdf.bounds()))
        throw Error("Nubis VDB: the SDF must have the NVDF's resolution and bounds");
    Field3D all(nvdf.resolution(), 4, nvdf.bounds(), {kModelingNames[0], kModelingNames[1], kModelingNames[2], "sdf"});
    for (int c = 0; c < 3; ++c) std::copy(nvdf.channel(c).begin(), nvdf.channel(c).end(), all.channel(c).begin());
    std::copy(sdf.channel(0).begin(), sdf.channel(0).end(), all.channel(3).begin());
    io::write_vdb(all, file);
}

Field3D read_nubis_vdb(const std::filesystem::path& file, const MemoryBudget* budget) {
    return io::read_vdb(file, {kModelingNames[0], kModelingNames[1], kModelingNames[2], "sdf"}, budget);
}

} // namespace atlas::volume

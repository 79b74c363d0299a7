// The Nubis voxel cloud pack layouts (see atlas/io/nubis_pack.h), through io's TGA slice and VDB code.
#include "atlas/io/nubis_pack.h"

#include "atlas/core/error.h"
#include "atlas/io/tga_slices.h"
#include "atlas/io/vdb.h"

#include <algorithm>

namespace atlas::io {
namespace {
constexpr const char* kModelingNames[3] = {"dimensional_profile", "detail_type", "density_scale"};

// Read by the io module's own TGA reader (uncompressed or RLE, either
// naming), not an image library: the pack's modeling slices carry A = 0,
// which premultiplying readers turn into black.
Field3D read_slices_rgba(const std::filesystem::path& first, Box3d bounds, int channels, std::vector<std::string> names,
                         const MemoryBudget* budget) {
    Field3D out = read_tga_slices(first, bounds, channels, budget);
    out.set_channel_names(std::move(names));
    return out;
}
} // namespace

std::vector<std::filesystem::path> write_nubis_modeling_tga(const Field3D& nvdf, const std::filesystem::path& dir, const std::string& stem,
                                                            const NubisTgaFormat& format) {
    if (nvdf.channels() != 3) throw Error("Nubis modeling TGA: expected a 3-channel NVDF, got " + std::to_string(nvdf.channels()) + " channels");
    io::SliceOptions o;
    o.naming = format.naming;
    o.rle = format.rle;
    o.channel_map = {0, 1, 2, -1};
    o.default_alpha = 0;
    return io::write_tga_slices(nvdf, dir, stem, o);
}

std::vector<std::filesystem::path> write_nubis_field_data_tga(const Field3D& sdf, const std::filesystem::path& dir, const std::string& stem,
                                                              const NubisTgaFormat& format) {
    io::SliceOptions o;
    o.naming = format.naming;
    o.rle = format.rle;
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
    // d = lo + v (hi - lo), v the stored R in [0, 1] (volume::decode_field_data's mapping).
    Field3D out(r.resolution(), 1, r.bounds(), {"sdf"}, budget);
    auto s = r.channel(0);
    auto d = out.channel(0);
    for (size_t i = 0; i < s.size(); ++i) d[i] = float(kNubisSdfMin + double(s[i]) * (kNubisSdfMax - kNubisSdfMin));
    return out;
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

} // namespace atlas::io

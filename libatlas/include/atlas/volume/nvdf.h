// atlas/volume/nvdf.h - Nubis Volume Data Fields: the modeling NVDF and the
// SDF "field data", and the layouts of Guerrilla's Nubis voxel cloud pack.
//
// Modeling NVDF: three channels, all in [0, 1]:
//   dimensional_profile  a gradient from the cloud surface inward (below)
//   detail_type          0 = wispy, 1 = billowy noise details
//   density_scale        multiplies the up-rezzed density
// Field data: the SDF (metres) mapped linearly from [range_min, range_max]
// (default [-256, 4096] m) to [0, 1] and clamped.
// Pack layouts (docs/formats.md, "Nubis voxel cloud pack"):
//   modeling TGA slices  (32-bit, RLE by default) R = dimensional_profile, G = detail_type,
//                        B = density_scale, A = 0 (value v -> round(255 v))
//   field-data TGA slices R = SDF encoded, d = R / 255 * 4352 - 256 metres,
//                        G = B = 0, A = 255
//   VDB                  float grids dimensional_profile, detail_type,
//                        density_scale and sdf (metres)
// Pure and deterministic; thread-safe.
#pragma once

#include "atlas/core/field.h"
#include "atlas/io/tga_slices.h"

#include <filesystem>
#include <string>
#include <vector>

namespace atlas {
class MemoryBudget;
}

namespace atlas::volume {

inline constexpr double kNubisSdfMin = -256.0;  // metres
inline constexpr double kNubisSdfMax = 4096.0;  // metres

// Dimensional profile from a signed distance field (metres, negative inside):
//   dp = saturate(-sdf / depth) ^ exponent
// 0 at and outside the surface, 1 at `depth` metres (> 0) inside and deeper.
// exponent > 0 shapes the ramp (1 = linear). Channel "dimensional_profile".
struct DimensionalProfileOptions {
    double depth = 64;   // metres
    double exponent = 1; // > 0
    int channel = 0;     // SDF channel
};
Field3D dimensional_profile(const Field3D& sdf, const DimensionalProfileOptions& options = {}, const MemoryBudget* budget = nullptr);

// SDF metres -> [0, 1] (clamped), channel "field_data"; range_max > range_min.
Field3D encode_field_data(const Field3D& sdf, double range_min = kNubisSdfMin, double range_max = kNubisSdfMax, int channel = 0,
                          const MemoryBudget* budget = nullptr);
// [0, 1] -> metres, channel "sdf".
Field3D decode_field_data(const Field3D& encoded, double range_min = kNubisSdfMin, double range_max = kNubisSdfMax, int channel = 0,
                          const MemoryBudget* budget = nullptr);

// Which channel of each input assemble_modeling_nvdf reads.
struct ModelingChannels {
    int dimensional_profile = 0, detail_type = 0, density_scale = 0;
};
// The three modeling channels in one field (same resolution and bounds; the
// channel of each input that `channels` names). Throws atlas::Error when the
// grids differ or a channel does not exist (naming the input).
Field3D assemble_modeling_nvdf(const Field3D& dimensional_profile, const Field3D& detail_type, const Field3D& density_scale,
                               const MemoryBudget* budget = nullptr, const ModelingChannels& channels = {});

// Pack interchange. Writers return the files written; readers throw
// atlas::Error naming the file when the layout does not match. Readers take
// either naming (STEM.001.tga or STEM(0).tga) and either encoding.
// `nvdf` has the three modeling channels (assemble_modeling_nvdf), `sdf` is in metres.
struct NubisTgaFormat {
    io::SliceNaming naming = io::SliceNaming::atlas; // nubis: STEM(0).tga ... as the pack's files
    bool rle = true;                                 // TGA type 10, as the pack's files
};
std::vector<std::filesystem::path> write_nubis_modeling_tga(const Field3D& nvdf, const std::filesystem::path& dir, const std::string& stem,
                                                            const NubisTgaFormat& format = {});
std::vector<std::filesystem::path> write_nubis_field_data_tga(const Field3D& sdf, const std::filesystem::path& dir, const std::string& stem,
                                                              const NubisTgaFormat& format = {});
Field3D read_nubis_modeling_tga(const std::filesystem::path& first_slice, Box3d bounds, const MemoryBudget* budget = nullptr);
// Returns the SDF in metres (channel "sdf").
Field3D read_nubis_field_data_tga(const std::filesystem::path& first_slice, Box3d bounds, const MemoryBudget* budget = nullptr);
void write_nubis_vdb(const Field3D& nvdf, const Field3D& sdf, const std::filesystem::path& file);
// Reads the four grids; returns channels dimensional_profile, detail_type,
// density_scale, sdf.
Field3D read_nubis_vdb(const std::filesystem::path& file, const MemoryBudget* budget = nullptr);

} // namespace atlas::volume

// atlas/io/nubis_pack.h - the file layouts of Guerrilla's Nubis voxel cloud pack
// (docs/formats.md, "Nubis voxel cloud pack"), over io's TGA slice and VDB code:
//   modeling TGA slices   (32-bit, RLE by default) R = dimensional_profile, G = detail_type,
//                         B = density_scale, A = 0 (value v -> round(255 v))
//   field-data TGA slices R = SDF encoded, d = R / 255 * 4352 - 256 metres, G = B = 0, A = 255
//   VDB                   float grids dimensional_profile, detail_type, density_scale and
//                         sdf (metres)
// Writers return the files written; readers throw atlas::Error naming the file when the
// layout does not match, and take either naming (STEM.001.tga or STEM(0).tga) and either
// encoding. The fields themselves (assemble_modeling_nvdf, encode_field_data) are the
// volume module's (atlas/volume/nvdf.h). Thread-safe; writes are atomic.
#pragma once

#include "atlas/core/field.h"
#include "atlas/io/tga_slices.h"

#include <filesystem>
#include <string>
#include <vector>

namespace atlas {
class MemoryBudget;
}

namespace atlas::io {

// The SDF range the pack's field data encodes (metres): [kNubisSdfMin, kNubisSdfMax] -> [0, 1].
inline constexpr double kNubisSdfMin = -256.0;
inline constexpr double kNubisSdfMax = 4096.0;

struct NubisTgaFormat {
    SliceNaming naming = SliceNaming::atlas; // nubis: STEM(0).tga ... as the pack's files
    bool rle = true;                         // TGA type 10, as the pack's files
};

// `nvdf` has the three modeling channels (volume::assemble_modeling_nvdf), `sdf` is in metres.
std::vector<std::filesystem::path> write_nubis_modeling_tga(const Field3D& nvdf, const std::filesystem::path& dir, const std::string& stem,
                                                            const NubisTgaFormat& format = {});
std::vector<std::filesystem::path> write_nubis_field_data_tga(const Field3D& sdf, const std::filesystem::path& dir, const std::string& stem,
                                                              const NubisTgaFormat& format = {});
Field3D read_nubis_modeling_tga(const std::filesystem::path& first_slice, Box3d bounds, const MemoryBudget* budget = nullptr);
// Returns the SDF in metres (channel "sdf").
Field3D read_nubis_field_data_tga(const std::filesystem::path& first_slice, Box3d bounds, const MemoryBudget* budget = nullptr);
void write_nubis_vdb(const Field3D& nvdf, const Field3D& sdf, const std::filesystem::path& file);
// Reads the four grids; returns channels dimensional_profile, detail_type, density_scale, sdf.
Field3D read_nubis_vdb(const std::filesystem::path& file, const MemoryBudget* budget = nullptr);

} // namespace atlas::io

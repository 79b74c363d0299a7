// atlas/compress/dds.h - the DDS container (DX10 header): 2D, 2D arrays, 3D volumes,
// mip chains; uncompressed and BC formats.
//
// Layout (as D3D expects): for each array element, for each mip level, the level's
// data; a volume level stores its depth slices one after another. BC formats store
// 4x4 blocks per slice, max(1, ceil(w/4)) x max(1, ceil(h/4)) blocks per slice; the
// texels beyond the image's edge in a partial block are padding (Atlas replicates
// the edge texels there). Level sizes are max(1, size >> level).
// Thread-safety: pure functions over values.
#pragma once

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

namespace atlas::compress {

// DXGI_FORMAT values of the formats Atlas reads and writes.
enum class DxgiFormat : uint32_t {
    R16G16B16A16_FLOAT = 10,
    R8G8B8A8_UNORM = 28,
    R32_FLOAT = 41,
    R16_FLOAT = 54,
    R16_UNORM = 56,
    R8_UNORM = 61,
    BC1_UNORM = 71,
    BC4_UNORM = 80,
    BC4_SNORM = 81,
    BC6H_UF16 = 95,
    BC6H_SF16 = 96,
    B4G4R4A4_UNORM = 115,
};

// "BC1_UNORM", ... ; throws atlas::Error for a value Atlas does not support.
const char* dxgi_format_name(DxgiFormat f);
bool is_block_compressed(DxgiFormat f);
// Bytes per 4x4 block (BC) or per texel (uncompressed).
int format_unit_bytes(DxgiFormat f);
// Channels the format stores (1 for R*, BC4; 3 for BC1, BC6H; 4 for RGBA formats).
int format_channels(DxgiFormat f);
// Bytes of one mip level of size w x h x d (d slices).
uint64_t level_bytes(DxgiFormat f, int w, int h, int d);

struct DdsTexture {
    DxgiFormat format = DxgiFormat::R8_UNORM;
    int width = 1, height = 1;
    int depth = 1;      // > 1 only for volumes
    bool volume = false; // TEXTURE3D resource
    int array_size = 1; // 2D arrays (volumes have 1)
    int mip_levels = 1;
    std::vector<uint8_t> data; // every subresource, in DDS order
    // Write the legacy FourCC header ("DXT1" / "ATI1") instead of DX10 when the
    // format has one and the texture is not an array (old readers such as
    // OpenImageIO 2.4 only know these for BC1). Reading accepts both.
    bool legacy_header = false;

    int level_width(int mip) const { return std::max(1, width >> mip); }
    int level_height(int mip) const { return std::max(1, height >> mip); }
    int level_depth(int mip) const { return volume ? std::max(1, depth >> mip) : 1; }
    uint64_t level_size(int mip) const { return level_bytes(format, level_width(mip), level_height(mip), level_depth(mip)); }
    // Byte offset of (array element, mip level) in data.
    uint64_t offset(int array_index, int mip) const;
    // Total bytes the description implies.
    uint64_t total_bytes() const;
};

// Serialises to the DDS file bytes ("DDS " + header + DX10 header + data).
// Throws atlas::Error if data.size() != total_bytes() or the description is invalid.
std::vector<uint8_t> encode_dds(const DdsTexture& tex);
// The bytes before the data (what encode_dds puts ahead of tex.data), with the
// same checks: a writer can put the header and tex.data on disk without a copy.
std::vector<uint8_t> encode_dds_header(const DdsTexture& tex);
// Parses DDS bytes (DX10 header, or the legacy DXT1 / ATI1 / BC4U / BC4S FourCCs);
// throws atlas::Error naming `what` on truncated or unsupported files.
DdsTexture decode_dds(const std::vector<uint8_t>& bytes, const std::string& what = "DDS data");

// Files: atlas/io/dds_file.h (io::write_dds_file, io::read_dds_file).

} // namespace atlas::compress

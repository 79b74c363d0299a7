// DDS container: header layout per the DirectX "DDS" programming guide.
#include "atlas/compress/dds.h"

#include "atlas/core/error.h"

#include <cstring>

namespace atlas::compress {

namespace {

constexpr uint32_t kMagic = 0x20534444; // "DDS "
constexpr uint32_t fourcc(char a, char b, char c, char d) {
    return uint32_t(uint8_t(a)) | (uint32_t(uint8_t(b)) << 8) | (uint32_t(uint8_t(c)) << 16) | (uint32_t(uint8_t(d)) << 24);
}
// DDS_HEADER flags
constexpr uint32_t DDSD_CAPS = 0x1, DDSD_HEIGHT = 0x2, DDSD_WIDTH = 0x4, DDSD_PITCH = 0x8, DDSD_PIXELFORMAT = 0x1000,
                   DDSD_MIPMAPCOUNT = 0x20000, DDSD_LINEARSIZE = 0x80000, DDSD_DEPTH = 0x800000;
constexpr uint32_t DDPF_FOURCC = 0x4;
constexpr uint32_t DDSCAPS_COMPLEX = 0x8, DDSCAPS_TEXTURE = 0x1000, DDSCAPS_MIPMAP = 0x400000;
constexpr uint32_t DDSCAPS2_VOLUME = 0x200000;
constexpr uint32_t kDim2D = 3, kDim3D = 4;

void put32(std::vector<uint8_t>& b, uint32_t v) {
    for (int i = 0; i < 4; ++i) b.push_back(uint8_t(v >> (8 * i)));
}
uint32_t get32(const std::vector<uint8_t>& b, size_t at) {
    return uint32_t(b[at]) | (uint32_t(b[at + 1]) << 8) | (uint32_t(b[at + 2]) << 16) | (uint32_t(b[at + 3]) << 24);
}

bool supported(uint32_t f) {
    switch (DxgiFormat(f)) {
    case DxgiFormat::R16G16B16A16_FLOAT: case DxgiFormat::R8G8B8A8_UNORM: case DxgiFormat::R32_FLOAT:
    case DxgiFormat::R16_FLOAT: case DxgiFormat::R16_UNORM: case DxgiFormat::R8_UNORM: case DxgiFormat::BC1_UNORM:
    case DxgiFormat::BC4_UNORM: case DxgiFormat::BC4_SNORM: case DxgiFormat::BC6H_UF16: case DxgiFormat::BC6H_SF16:
    case DxgiFormat::B4G4R4A4_UNORM: return true;
    }
    return false;
}

} // namespace

const char* dxgi_format_name(DxgiFormat f) {
    switch (f) {
    case DxgiFormat::R16G16B16A16_FLOAT: return "R16G16B16A16_FLOAT";
    case DxgiFormat::R8G8B8A8_UNORM: return "R8G8B8A8_UNORM";
    case DxgiFormat::R32_FLOAT: return "R32_FLOAT";
    case DxgiFormat::R16_FLOAT: return "R16_FLOAT";
    case DxgiFormat::R16_UNORM: return "R16_UNORM";
    case DxgiFormat::R8_UNORM: return "R8_UNORM";
    case DxgiFormat::BC1_UNORM: return "BC1_UNORM";
    case DxgiFormat::BC4_UNORM: return "BC4_UNORM";
    case DxgiFormat::BC4_SNORM: return "BC4_SNORM";
    case DxgiFormat::BC6H_UF16: return "BC6H_UF16";
    case DxgiFormat::BC6H_SF16: return "BC6H_SF16";
    case DxgiFormat::B4G4R4A4_UNORM: return "B4G4R4A4_UNORM";
    }
    throw Error("unsupported DXGI format " + std::to_string(uint32_t(f)));
}

bool is_block_compressed(DxgiFormat f) {
    return f == DxgiFormat::BC1_UNORM || f == DxgiFormat::BC4_UNORM || f == DxgiFormat::BC4_SNORM ||
           f == DxgiFormat::BC6H_UF16 || f == DxgiFormat::BC6H_SF16;
}

int format_unit_bytes(DxgiFormat f) {
    switch (f) {
    case DxgiFormat::BC1_UNORM: case DxgiFormat::BC4_UNORM: case DxgiFormat::BC4_SNORM: return 8;
    case DxgiFormat::BC6H_UF16: case DxgiFormat::BC6H_SF16: return 16;
    case DxgiFormat::R8_UNORM: return 1;
    case DxgiFormat::R16_UNORM: case DxgiFormat::R16_FLOAT: case DxgiFormat::B4G4R4A4_UNORM: return 2;
    case DxgiFormat::R32_FLOAT: case DxgiFormat::R8G8B8A8_UNORM: return 4;
    case DxgiFormat::R16G16B16A16_FLOAT: return 8;
    }
    throw Error("unsupported DXGI format " + std::to_string(uint32_t(f)));
}

int format_channels(DxgiFormat f) {
    switch (f) {
    case DxgiFormat::BC1_UNORM: case DxgiFormat::BC6H_UF16: case DxgiFormat::BC6H_SF16: return 3;
    case DxgiFormat::R8G8B8A8_UNORM: case DxgiFormat::R16G16B16A16_FLOAT: case DxgiFormat::B4G4R4A4_UNORM: return 4;
    default: return 1;
    }
}

uint64_t level_bytes(DxgiFormat f, int w, int h, int d) {
    if (is_block_compressed(f))
        return uint64_t(std::max(1, (w + 3) / 4)) * uint64_t(std::max(1, (h + 3) / 4)) * uint64_t(d) * uint64_t(format_unit_bytes(f));
    return uint64_t(w) * uint64_t(h) * uint64_t(d) * uint64_t(format_unit_bytes(f));
}

uint64_t DdsTexture::offset(int array_index, int mip) const {
    uint64_t per_element = 0;
    for (int m = 0; m < mip_levels; ++m) per_element += level_size(m);
    uint64_t off = per_element * uint64_t(array_index);
    for (int m = 0; m < mip; ++m) off += level_size(m);
    return off;
}

uint64_t DdsTexture::total_bytes() const { return offset(array_size, 0); }

static void validate(const DdsTexture& t, const std::string& what) {
    if (!supported(uint32_t(t.format))) throw Error(what + ": unsupported DXGI format " + std::to_string(uint32_t(t.format)));
    if (t.width < 1 || t.height < 1 || t.depth < 1 || t.array_size < 1 || t.mip_levels < 1)
        throw Error(what + ": width, height, depth, array size and mip count must be >= 1");
    if (t.width > 65536 || t.height > 65536 || t.depth > 65536 || t.array_size > 65536)
        throw Error(what + ": dimensions above 65536 are not supported");
    if (uint64_t(t.width) * uint64_t(t.height) * uint64_t(t.depth) * uint64_t(t.array_size) > (uint64_t(1) << 34))
        throw Error(what + ": more than 2^34 texels (width x height x depth x array size) is not supported");
    if (!t.volume && t.depth != 1) throw Error(what + ": depth > 1 requires a volume texture");
    if (t.volume && t.array_size != 1) throw Error(what + ": volume textures cannot be arrays");
    int full = 1;
    for (int s = std::max({t.width, t.height, t.volume ? t.depth : 1}); s > 1; s >>= 1) ++full;
    if (t.mip_levels > full) throw Error(what + ": " + std::to_string(t.mip_levels) + " mip levels for a size with only " + std::to_string(full));
}

std::vector<uint8_t> encode_dds(const DdsTexture& t) {
    std::vector<uint8_t> b = encode_dds_header(t);
    b.insert(b.end(), t.data.begin(), t.data.end());
    return b;
}

std::vector<uint8_t> encode_dds_header(const DdsTexture& t) {
    validate(t, "encode_dds");
    if (t.data.size() != t.total_bytes())
        throw Error("encode_dds: data holds " + std::to_string(t.data.size()) + " bytes, the description needs " + std::to_string(t.total_bytes()));
    std::vector<uint8_t> b;
    b.reserve(148);
    put32(b, kMagic);
    put32(b, 124);
    uint32_t flags = DDSD_CAPS | DDSD_HEIGHT | DDSD_WIDTH | DDSD_PIXELFORMAT;
    flags |= is_block_compressed(t.format) ? DDSD_LINEARSIZE : DDSD_PITCH;
    if (t.mip_levels > 1) flags |= DDSD_MIPMAPCOUNT;
    if (t.volume) flags |= DDSD_DEPTH;
    put32(b, flags);
    put32(b, uint32_t(t.height));
    put32(b, uint32_t(t.width));
    const uint64_t pitch = is_block_compressed(t.format) ? level_bytes(t.format, t.width, t.height, 1)
                                                         : uint64_t(t.width) * uint64_t(format_unit_bytes(t.format));
    put32(b, uint32_t(pitch));
    put32(b, uint32_t(t.volume ? t.depth : 0));
    put32(b, uint32_t(t.mip_levels));
    for (int i = 0; i < 11; ++i) put32(b, 0);
    // DDS_PIXELFORMAT: FourCC "DX10", the real format is in the extended header.
    uint32_t legacy = 0;
    if (t.legacy_header && t.array_size == 1) {
        if (t.format == DxgiFormat::BC1_UNORM) legacy = fourcc('D', 'X', 'T', '1');
        if (t.format == DxgiFormat::BC4_UNORM) legacy = fourcc('A', 'T', 'I', '1');
        if (t.format == DxgiFormat::BC4_SNORM) legacy = fourcc('B', 'C', '4', 'S');
    }
    put32(b, 32);
    put32(b, DDPF_FOURCC);
    put32(b, legacy ? legacy : fourcc('D', 'X', '1', '0'));
    for (int i = 0; i < 5; ++i) put32(b, 0);
    uint32_t caps = DDSCAPS_TEXTURE;
    if (t.mip_levels > 1) caps |= DDSCAPS_MIPMAP | DDSCAPS_COMPLEX;
    if (t.volume || t.array_size > 1) caps |= DDSCAPS_COMPLEX;
    put32(b, caps);
    put32(b, t.volume ? DDSCAPS2_VOLUME : 0);
    put32(b, 0);
    put32(b, 0);
    put32(b, 0);
    if (legacy) return b;
    // DDS_HEADER_DXT10
    put32(b, uint32_t(t.format));
    put32(b, t.volume ? kDim3D : kDim2D);
    put32(b, 0); // misc flag (not a cube map)
    put32(b, uint32_t(t.array_size));
    put32(b, 0); // alpha mode unknown
    return b;
}

DdsTexture decode_dds(const std::vector<uint8_t>& b, const std::string& what) {
    if (b.size() < 128 || get32(b, 0) != kMagic) throw Error(what + ": not a DDS file (missing 'DDS ' magic or header)");
    if (get32(b, 4) != 124) throw Error(what + ": DDS header size is not 124");
    DdsTexture t;
    const uint32_t flags = get32(b, 8);
    t.height = int(get32(b, 12));
    t.width = int(get32(b, 16));
    const uint32_t depth = get32(b, 24);
    const uint32_t mips = get32(b, 28);
    t.mip_levels = (flags & DDSD_MIPMAPCOUNT) && mips > 0 ? int(mips) : 1;
    const uint32_t pf_flags = get32(b, 80), four = get32(b, 84);
    const uint32_t caps2 = get32(b, 112);
    size_t data_at = 128;
    if (!(pf_flags & DDPF_FOURCC)) throw Error(what + ": only FourCC / DX10 DDS files are supported");
    if (four == fourcc('D', 'X', '1', '0')) {
        if (b.size() < 148) throw Error(what + ": truncated DX10 header");
        const uint32_t f = get32(b, 128), dim = get32(b, 132), misc = get32(b, 136), arr = get32(b, 140);
        if (!supported(f)) throw Error(what + ": unsupported DXGI format " + std::to_string(f));
        if (misc & 0x4) throw Error(what + ": cube maps are not supported");
        if (dim != kDim2D && dim != kDim3D) throw Error(what + ": only 2D and 3D textures are supported (dimension " + std::to_string(dim) + ")");
        t.format = DxgiFormat(f);
        t.volume = dim == kDim3D;
        t.array_size = int(std::max<uint32_t>(1, arr));
        data_at = 148;
    } else if (four == fourcc('D', 'X', 'T', '1')) t.format = DxgiFormat::BC1_UNORM;
    else if (four == fourcc('A', 'T', 'I', '1') || four == fourcc('B', 'C', '4', 'U')) t.format = DxgiFormat::BC4_UNORM;
    else if (four == fourcc('B', 'C', '4', 'S')) t.format = DxgiFormat::BC4_SNORM;
    else throw Error(what + ": unsupported FourCC");
    t.legacy_header = data_at == 128;
    if (caps2 & DDSCAPS2_VOLUME) t.volume = true;
    t.depth = t.volume ? int(std::max<uint32_t>(1, depth)) : 1;
    validate(t, what);
    const uint64_t need = t.total_bytes();
    if (b.size() - data_at < need)
        throw Error(what + ": truncated: " + std::to_string(b.size() - data_at) + " data bytes, expected " + std::to_string(need));
    t.data.assign(b.begin() + std::ptrdiff_t(data_at), b.begin() + std::ptrdiff_t(data_at + need));
    return t;
}

} // namespace atlas::compress

// Format names and properties for the texture API (texture.h).
#include "atlas/compress/texture.h"

#include "atlas/core/error.h"

namespace atlas::compress {

namespace {
struct FormatRow {
    Format format;
    const char* name;
    DxgiFormat dxgi;
};
constexpr FormatRow kFormats[] = {
    {Format::Bc1, "bc1", DxgiFormat::BC1_UNORM},
    {Format::Bc1Scalar, "bc1-scalar", DxgiFormat::BC1_UNORM},
    {Format::Bc4, "bc4", DxgiFormat::BC4_UNORM},
    {Format::Bc4Snorm, "bc4-snorm", DxgiFormat::BC4_SNORM},
    {Format::Bc6hUf16, "bc6h", DxgiFormat::BC6H_UF16},
    {Format::Bc6hSf16, "bc6h-sf16", DxgiFormat::BC6H_SF16},
    {Format::R8, "r8", DxgiFormat::R8_UNORM},
    {Format::R16, "r16", DxgiFormat::R16_UNORM},
    {Format::R16F, "r16f", DxgiFormat::R16_FLOAT},
    {Format::R32F, "r32f", DxgiFormat::R32_FLOAT},
    {Format::Rgba8, "rgba8", DxgiFormat::R8G8B8A8_UNORM},
    {Format::Rgba16F, "rgba16f", DxgiFormat::R16G16B16A16_FLOAT},
    {Format::Rgba4, "rgba4", DxgiFormat::B4G4R4A4_UNORM},
};
} // namespace

const char* format_name(Format f) {
    for (const auto& r : kFormats)
        if (r.format == f) return r.name;
    return "?";
}

std::string format_names() {
    std::string list;
    for (const auto& r : kFormats) list += std::string(list.empty() ? "" : ", ") + r.name;
    return list;
}

Format parse_format(const std::string& name) {
    for (const auto& r : kFormats)
        if (name == r.name) return r.format;
    throw Error("unknown texture format '" + name + "' (expected one of: " + format_names() + ")");
}

DxgiFormat dxgi_format(Format f) {
    for (const auto& r : kFormats)
        if (r.format == f) return r.dxgi;
    throw Error("unknown texture format");
}

} // namespace atlas::compress

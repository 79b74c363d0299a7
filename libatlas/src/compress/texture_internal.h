// Internal: value mapping and level decoding shared by encode, verify and read.
#pragma once

#include "atlas/compress/bc1_scalar.h"
#include "atlas/compress/texture.h"

#include <vector>

namespace atlas::compress::detail {

enum class MapKind { Unorm, Snorm, Float };

struct Mapping {
    MapKind kind = MapKind::Unorm;
    float lo = 0, hi = 1;
    double scale() const { return kind == MapKind::Float ? 1.0 : kind == MapKind::Snorm ? (double(hi) - lo) / 2.0 : double(hi) - lo; }
    float to_norm(float v) const {
        if (kind == MapKind::Float) return v;
        const float u = (v - lo) / (hi - lo);
        return kind == MapKind::Snorm ? u * 2.0f - 1.0f : u;
    }
    float to_src(float n) const {
        if (kind == MapKind::Float) return n;
        const float u = kind == MapKind::Snorm ? (n + 1.0f) * 0.5f : n;
        return lo + u * (hi - lo);
    }
    // The engine's reconstruction lo + n (hi - lo) (SNORM: (n + 1) / 2) in double: what
    // the guarantees are stated against (a decoder computing in double).
    double to_src_exact(double n) const {
        if (kind == MapKind::Float) return n;
        const double u = kind == MapKind::Snorm ? (n + 1.0) * 0.5 : n;
        return double(lo) + u * (double(hi) - double(lo));
    }
};

MapKind map_kind(DxgiFormat f);

// DDS stores rows top-down (row 0 is the image's top); Atlas fields are y-up
// (y = 0 is the bottom row, as in EXR/PNG/TGA output where the top row is y = h-1).
// Maps a texel index (x fastest, then row, then slice) of a w x h x d level between
// the two orders; the map is its own inverse.
inline size_t dds_row_flip(size_t i, int w, int h) {
    const size_t W = size_t(w), H = size_t(h);
    const size_t x = i % W, y = (i / W) % H, z = i / (W * H);
    return (z * H + (H - 1 - y)) * W + x;
}

// Level `mip` of array element `layer`, decoded to normalized channel planes
// (x fastest, then y, then z); lo/hi give the decoder's interval (equal except
// for the Conformant model).
struct DecodedLevel {
    int w = 0, h = 0, d = 0, channels = 0;
    std::vector<std::vector<float>> lo, hi;
};
// Slices [z0, z1) of one level (z1 < 0: to the last slice); `d` is z1 - z0.
// A verify pass decodes a volume a few slices at a time, so its buffers stay
// small and are reused instead of touching a whole volume's fresh memory.
DecodedLevel decode_level(const DdsTexture& tex, int layer, int mip, Decoder decoder, bool bc1_scalar,
                          const ScalarUnpack& unpack, int z0 = 0, int z1 = -1);

} // namespace atlas::compress::detail

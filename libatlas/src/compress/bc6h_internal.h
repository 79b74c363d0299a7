// Internal: BC6H mode table, the logical block (mode, partition, endpoints, indices)
// and the integer steps of the D3D11 decoding, shared by the decoder and the encoder
// so that the encoder's palettes are exactly what the decoder produces.
#pragma once

#include <cstdint>

namespace atlas::compress::detail::bc6h {

struct ModeInfo {
    uint8_t header;    // value of the mode bits (2 bits for modes 1-2, else 5), LSB first
    uint8_t header_bits;
    uint8_t regions;   // 1 or 2
    uint8_t w;         // endpoint precision (bits)
    uint8_t d[3];      // stored bits of the other endpoints per channel (= w when not transformed)
    bool transformed;  // other endpoints stored as deltas from endpoint 0
};

// Index 0..13 = the specification's modes 1..14.
extern const ModeInfo kModes[14];

// Two-region shapes: bit t set = texel t in region 1.
extern const uint16_t kPartitions[32];
// The second region's anchor texel (its index is stored with one bit less).
extern const uint8_t kAnchor2[32];
extern const int kWeights3[8];
extern const int kWeights4[16];

// The mode index 0..13 for a block's header, or -1 for a reserved header.
int mode_of(const uint8_t block[16]);

// A block in decoded form. Endpoints are the w-bit values after the inverse transform
// and sign extension (signed formats: two's complement in w bits).
struct Logical {
    int mode = 10;
    int partition = 0;
    int e[4][3] = {}; // [region*2 + end][channel]
    uint8_t idx[16] = {};
};

// Parses a block (mode >= 0). Returns false for reserved headers.
bool unpack(const uint8_t block[16], bool is_signed, Logical& out);

// Writes a block. The endpoints must be representable (delta ranges are checked by
// fits()); anchor indices must have their top bit clear.
void pack(const Logical& in, bool is_signed, uint8_t block[16]);

// True when the endpoints of `e` can be stored in mode `m` (delta ranges, w-bit range;
// signed codes limited to +-(2^(w-1) - 1), the encoder's choice).
bool fits(int m, const int e[4][3], bool is_signed);

// Unquantize a w-bit endpoint to the 16-bit interpolation domain (spec formulas).
inline int unquantize(int v, int w, bool is_signed) {
    if (!is_signed) {
        if (w >= 15 || v == 0) return v;
        if (v == (1 << w) - 1) return 0xFFFF;
        return ((v << 16) + 0x8000) >> w;
    }
    if (w >= 16) return v;
    const bool neg = v < 0;
    const int a = neg ? -v : v;
    int u;
    if (a == 0) u = 0;
    else if (a >= (1 << (w - 1)) - 1) u = 0x7FFF;
    else u = ((a << 15) + 0x4000) >> (w - 1);
    return neg ? -u : u;
}

inline int interpolate(int a, int b, int weight) { return (a * (64 - weight) + b * weight + 32) >> 6; }

// The 16-bit interpolation result to half bits (UF16: *31/64; SF16: magnitude *31/32).
inline uint16_t finish(int v, bool is_signed) {
    if (!is_signed) return uint16_t((v * 31) >> 6);
    if (v < 0) return uint16_t(0x8000 | (((-v) * 31) >> 5));
    return uint16_t((v * 31) >> 5);
}

inline int region_of(int partition, int regions, int t) { return regions == 2 ? (kPartitions[partition] >> t) & 1 : 0; }
inline bool is_anchor(int partition, int regions, int t) { return t == 0 || (regions == 2 && t == kAnchor2[partition]); }

} // namespace atlas::compress::detail::bc6h

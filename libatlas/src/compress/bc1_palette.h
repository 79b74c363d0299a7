// Internal: BC1 palettes as decoder-set intervals (shared by bc1 and bc1-scalar).
#pragma once

#include "atlas/compress/decoder_model.h"
#include "palette_search.h"

#include <cstdint>

namespace atlas::compress::detail {

// bc1_palette through precomputed per-channel tables (identical values).
void bc1_palette_fast(uint16_t c0, uint16_t c1, Decoder d, float out[4][3]);

// The 4 palette values of one channel (five-bit R/B or six-bit G endpoints a, b;
// `four`: the 4-colour mode, c0 > c1) under a decoder, from the same tables.
const float* bc1_channel_palette(Decoder d, bool four, bool six, int a, int b);

// Per-channel interval palette of (c0, c1) over a decoder set.
void bc1_interval_palette(uint16_t c0, uint16_t c1, DecoderSet set, Palette<3>& p);

// The same intervals channel-major (lo[c][i]: channel c of entry i, i < 4), built 4 entries
// at a time from the channel tables: the same floats as bc1_interval_palette (test
// Bc1Eval.ChannelMajorPaletteEqualsIntervalPalette).
struct Bc1PaletteCm {
    alignas(16) float lo[3][4];
    alignas(16) float hi[3][4];
    alignas(16) float ref[3][4];
};
void bc1_interval_palette_cm(uint16_t c0, uint16_t c1, DecoderSet set, Bc1PaletteCm& p);

inline void write_bc1_block(uint16_t c0, uint16_t c1, const uint8_t idx[16], uint8_t out[8]) {
    out[0] = uint8_t(c0); out[1] = uint8_t(c0 >> 8);
    out[2] = uint8_t(c1); out[3] = uint8_t(c1 >> 8);
    uint32_t bits = 0;
    for (int t = 0; t < 16; ++t) bits |= uint32_t(idx[t] & 3) << (2 * t);
    for (int i = 0; i < 4; ++i) out[4 + i] = uint8_t(bits >> (8 * i));
}

} // namespace atlas::compress::detail

// atlas/compress/bc1.h - BC1 (RGB, 4 bits per texel).
//
// Block: little-endian 565 colours c0, c1 (R in bits 15..11, G 10..5, B 4..0), then
// 16 2-bit indices, texel 0 in the lowest bits. c0 > c1 (as integers) selects the
// 4-colour palette {c0, c1, (2c0+c1)/3, (c0+2c1)/3}, otherwise the 3-colour palette
// {c0, c1, (c0+c1)/2, black} (Atlas writes no alpha; index 3 decodes to RGB 0).
//
// Implemented in bc1_encode.cpp, bc1_palette.cpp, bc1_scalar.cpp (src/compress/).
#pragma once

#include "atlas/compress/block.h"

#include <cstdint>

namespace atlas::compress {

// The 4 palette colours (RGB in [0,1]) of an endpoint pair under one decoder model.
// Conformant returns the Reference palette (the centre of its tolerance interval).
void bc1_palette(uint16_t c0, uint16_t c1, Decoder d, float out[4][3]);

// Decodes one block: rgb[3*t + c] for texel t (row-major in the block), channel c.
void decode_bc1_block(const uint8_t block[8], Decoder d, float rgb[48]);

// Encodes 16 RGB texels (rgb[3*t + c], nominally in [0,1]) minimising the max
// per-channel error under options.decoders, then the squared Reference error.
// Fast: principal-axis endpoints only; Normal: + the box diagonals and 3 rounds of
// +-1 endpoint refinement; Best: more starts and rounds. Thread-safe, deterministic.
BlockResult encode_bc1_block(const float rgb[48], const BlockOptions& options, uint8_t out[8]);

} // namespace atlas::compress

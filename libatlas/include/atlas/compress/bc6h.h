// atlas/compress/bc6h.h - BC6H (RGB half float, 8 bits per texel), UF16 and SF16.
//
// Block: 128 bits read LSB first. A 2- or 5-bit mode header selects one of 14 modes
// (10 two-region modes with one of 32 partition shapes and 3-bit indices, 4 one-region
// modes with 4-bit indices); 4 further header values are reserved and decode to 0.
// Decoding follows the D3D11 functional specification bit-exactly (integer math), so
// every conforming decoder produces the same halves: there is no decoder tolerance and
// DecoderSet does not apply. Texels are row-major in the block (t = x + 4*y), channel c
// of texel t at [3*t + c]. All functions are pure: thread-safe, deterministic.
//
// Implemented in bc6h_encode.cpp, bc6h_decode.cpp (src/compress/).
#pragma once

#include "atlas/compress/block.h"

#include <cstdint>

namespace atlas::compress {

// Decodes one block to half-float bit patterns (UF16: 0..0x7BFF; SF16: sign-magnitude,
// magnitude 0..0x7BFF). Reserved modes give all zeros.
void decode_bc6h_block_half(const uint8_t block[16], bool is_signed, uint16_t out[48]);

// Decodes one block to float (the halves above, converted exactly).
void decode_bc6h_block(const uint8_t block[16], bool is_signed, float out[48]);

// The block's mode as the specification numbers it (1..14), or 0 for a reserved header.
int bc6h_block_mode(const uint8_t block[16]);

// Encodes 16 RGB texels given as float in source units (no mapping: BC6H stores values).
// Representable range: UF16 [0, 65504], SF16 [-65504, 65504]; values outside are clamped
// for the search and the error is measured against the unclamped input (texture-level
// callers reject them before, see texture.h). Throws atlas::Error naming the texel on NaN
// or Inf. Objective: minimise max |decoded - source| over texels and channels (float
// values), then the squared error. Search per quality:
//   Fast   one-region modes only (10-bit direct and the most precise delta mode that fits);
//   Normal + two-region modes on the 4 partitions a principal-axis estimate ranks best,
//          then one round of +-1 endpoint refinement;
//   Best   all 14 modes, all 32 partitions, several refinement rounds on the best few.
// A block that misses options.max_error at Fast/Normal is re-encoded with Best. The search
// is not exhaustive: a miss is the best error found. options.one_sided_below and
// options.decoders are ignored (the caller refuses one-sided BC6H). The returned
// max_error is measured on the written block through decode_bc6h_block.
BlockResult encode_bc6h_block(const float rgb[48], bool is_signed, const BlockOptions& options, uint8_t out[16]);

} // namespace atlas::compress

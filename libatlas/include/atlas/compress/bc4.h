// atlas/compress/bc4.h - BC4 (one channel, 4 bits per texel) UNORM and SNORM.
//
// Block: byte 0 = endpoint e0, byte 1 = e1 (uint8 for UNORM, int8 for SNORM; -128
// reads as -127), then 16 3-bit indices, texel 0 in the lowest bits. e0 > e1 selects
// 8 interpolated values, otherwise 6 plus the exact 0 (SNORM: -1) and 1.
//
// Implemented in bc4_decode.cpp (the decoders), bc4_tables.cpp (Bc4Encoder's tables and
// constructor), bc4_search.cpp (encode, encode_blocks, encode_exhaustive) and bc4_avx2.cpp
// (encode's AVX2 path), under libatlas/src/compress.
#pragma once

#include "atlas/compress/block.h"

#include <array>
#include <cstdint>
#include <memory>

namespace atlas::compress {

// Decodes one block under a decoder model; values in [0,1] (UNORM) or [-1,1] (SNORM).
// Conformant returns the Reference values (the centre of its tolerance interval).
void decode_bc4_block(const uint8_t block[8], bool snorm, Decoder d, float out[16]);

// The worst-case interval [lo, hi] of every texel of a block over a decoder set.
void decode_bc4_interval(const uint8_t block[8], bool snorm, DecoderSet set, float lo[16], float hi[16]);

// Encodes BC4 blocks. Construction precomputes the palettes of all 65,536 endpoint
// pairs for the decoder set (about 12 MB with the search-pruning tables); encode() is const and thread-safe.
// The tables are shared: encoders of the same kind and options (within a process, the
// last four kinds) reuse them instead of building them again for every texture.
// Objective: minimise the block's max error under the decoder set (subject to
// decoded <= source when one-sided), then the squared Reference error. The encoder's
// palette bounds are the exact palette values rounded outward (a decoder computing in
// double stays inside them); decode_bc4_interval reports the float values.
// Quality::Best (and any block missing options.max_error) searches all pairs and is
// therefore optimal for that objective.
class Bc4Encoder {
public:
    Bc4Encoder(bool snorm, const BlockOptions& options);
    ~Bc4Encoder();
    // src: 16 texels in the normalized range (values outside are measured as is).
    BlockResult encode(const float src[16], uint8_t out[8]) const;
    // `count` blocks (16 texels each, consecutive) into `count` 8-byte blocks and
    // results: the same as encode() on each, faster on runs of 8-bit-like blocks (their
    // kinds are sorted out first, so no late branch serializes the blocks).
    void encode_blocks(const float* src, size_t count, uint8_t* out, BlockResult* results) const;
    // The exhaustive search regardless of quality (exposed for tests).
    BlockResult encode_exhaustive(const float src[16], uint8_t out[8]) const;
    const BlockOptions& options() const { return options_; }

private:
    struct Tables;
    bool snorm_;
    BlockOptions options_;
    std::shared_ptr<Tables> tables_;
};

} // namespace atlas::compress

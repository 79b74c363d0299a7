// atlas/compress/bc1_scalar.h - one scalar of up to 16 bits in BC1's RGB565 endpoints
// (the Nubis^3 field-data encoding).
//
// A value v (normalized, [0,1]) is written as a 565 colour: R holds the most
// significant part, G the next, B the least. The shader samples the texture with
// bilinear filtering and unpacks with dot(rgb, weights). Because filtering is linear
// per channel and the dot product is linear, the unpacked filtered value is the
// filtered unpacked value (up to the filter's weight precision).
//
// Weights are derived from the decoder models (docs/compression.md): w_r = 1,
// w_g = the largest step between consecutive R levels, w_b = w_g times the largest
// step between consecutive G levels, over the decoders of the set. Then every gap
// left by one channel's quantisation is covered by the next channel's range, and a
// greedy round-down reaches any value in [0, 1] from below within w_b * (largest B
// step). With 8-bit decoder models in the set this gives exactly Nubis's
// (1, 9/255, 9/255 * 5/255) = (1, 0.0352941, 0.00069204).
#pragma once

#include "atlas/compress/block.h"

#include <array>
#include <cstdint>

namespace atlas::compress {

struct ScalarUnpack {
    std::array<float, 3> weights{1.0f, 0.0f, 0.0f}; // dot(rgb, weights) = value
    float max_value = 1.0f;    // weights[0] + weights[1] + weights[2]: largest decodable value
    float endpoint_step = 0.0f; // largest gap between round-down endpoints (worst decoder)
    DecoderSet decoders = kAllDecoders;
};

// The unpack weights for a decoder set (see above). Pure.
ScalarUnpack bc1_scalar_unpack(DecoderSet decoders);

// Decodes the 16 scalars of a block under one decoder model.
void decode_bc1_scalar_block(const uint8_t block[8], Decoder d, const ScalarUnpack& unpack, float out[16]);

// Encodes 16 scalars in [0,1] (max error, then squared error; one-sided when asked).
// One-sided is always feasible, and never by leaving a texel on the 3-colour mode's
// exact black: the candidates include the constant block of the minimum's round-down
// (an endpoint <= the minimum under every decoder, checked with the palette's own
// bounds), so a block's error is at most its spread plus one endpoint's slack. Normal
// adds a minimax fit of evenly spaced entries to the block's value clusters and
// retargets entries just below texel values (docs/compression.md, "bc1-scalar").
// Reported errors and the one-sided check bound the exact values (2^-21 relative), so
// they hold for a decoder computing in double. Pure and thread-safe.
// options.decoders must equal unpack.decoders (the weights belong to that set).
BlockResult encode_bc1_scalar_block(const float src[16], const ScalarUnpack& unpack, const BlockOptions& options,
                                    uint8_t out[8]);

} // namespace atlas::compress

// atlas/compress/block.h - options and results shared by the 4x4 block encoders.
//
// Block encoders take 16 texels in row-major order (texel t = x + 4*y) as float in
// the format's normalized range (UNORM [0,1], SNORM [-1,1]) and write the block's
// bytes. Errors are in the same normalized units. All block functions are pure:
// safe to call from any number of threads, same input -> same bytes.
#pragma once

#include "atlas/compress/decoder_model.h"

#include <cstdint>

namespace atlas::compress {

// Encoder effort. Fast and Normal try a few endpoint candidates; Best searches
// more (BC4: all 65,536 endpoint pairs, provably optimal for the objective).
enum class Quality { Fast, Normal, Best };
const char* quality_name(Quality q);
Quality parse_quality(const char* name); // throws atlas::Error on an unknown name

struct BlockOptions {
    Quality quality = Quality::Normal;
    // Target max |decoded - source| per texel (normalized units); < 0 means none.
    // When the chosen quality misses it, BC4 falls back to the exhaustive search
    // and BC1 to a wider search before giving up (the result then says so).
    float max_error = -1.0f;
    // Every decoded texel <= its source under every decoder in `decoders`.
    bool one_sided_below = false;
    DecoderSet decoders = kAllDecoders;
    bool operator==(const BlockOptions&) const = default;
};

// What one encoded block achieved under the decoder set of its options.
struct BlockResult {
    // max over texels, channels and decoders of |decoded - source| (for the
    // Conformant model, the worst value inside its tolerance interval). BC4 and
    // bc1-scalar bound the exact decoded values (a decoder computing in double stays
    // within it, and one-sided holds for it), not only the float ones.
    float max_error = 0;
    // sum over texels and channels of the squared Reference-decoder error.
    double sum_sq = 0;
    // false when one-sided was asked and no candidate satisfied it (BC1 RGB only;
    // BC4 and bc1-scalar can always satisfy it through their exact 0 entry).
    bool one_sided_ok = true;
};

} // namespace atlas::compress

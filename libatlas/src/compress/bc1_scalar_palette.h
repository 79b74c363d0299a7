// Internal: bc1-scalar interval palettes from precomputed weighted channel tables.
//
// The scalar of a palette entry under a decoder is dot(rgb, w) = (R*wR + G*wG) + B*wB,
// each product a float. Precomputing every product per channel endpoint pair gives
// the very same floats, so a palette costs 3 loads and 2 adds per decoder instead of
// a palette decode and a dot product per entry.
#pragma once

#include "atlas/compress/bc1_scalar.h"
#include "palette_search.h"

#include <cstdint>
#include <memory>

namespace atlas::compress::detail {

// Decoded value of a channel level i (bits = 5 or 6) under a decoder's endpoint rule.
float channel_level_value(int i, int bits, Decoder d);

struct ScalarTables {
    ScalarUnpack unpack;
    // Decoded channel levels: the largest over the set (round-down safety) and Reference.
    float hi5[32], hi6[64], ref5[32], ref6[64];
    // Distinct value models of the set (Conformant's values are Reference's); model 0
    // is always Reference (needed for the squared-error tie break).
    int models = 0;
    bool in_set[kDecoderCount] = {}; // model m contributes to the interval
    bool conformant = false;
    // Weighted channel palettes [model][four][a][b][entry].
    float r[kDecoderCount][2][32][32][4];
    float g[kDecoderCount][2][64][64][4];
    float b[kDecoderCount][2][32][32][4];
    // Conformant tolerance of a channel pair times its weight.
    float tr[32][32], tg[64][64], tb[32][32];
    // The decoders' largest disagreement on an endpoint value (sum over the channels of
    // the widest level spread times the weight) plus the largest endpoint step: how far
    // one endpoint can be from a value it stands for from below.
    float endpoint_slack = 0;
};

// Tables for an unpack (weights and decoder set). Those of bc1_scalar_unpack(set)
// are built once per set and shared (immutable after a thread-safe initialisation);
// other weights get tables built into `local`.
const ScalarTables& scalar_tables(const ScalarUnpack& u, std::unique_ptr<ScalarTables>& local);

// Relative widening of an interval bound: the float palette rounds 4 times (channel
// value, product, two sums), each by at most 2^-24 relative, all terms >= 0, so the
// exact value (and a double-precision decoder's, ~1e-16 off it) lies within 2^-21
// relative of the float result.
constexpr float kScalarExactMargin = 1.0f / 2097152.0f; // 2^-21
inline float widen_up(float x) { return x + (x < 0 ? -x : x) * kScalarExactMargin; }
inline float widen_down(float x) { return x - (x < 0 ? -x : x) * kScalarExactMargin; }

// Interval palette of (c0, c1): the float values of evaluating each decoder's palette
// and the dot product per entry (ref), with lo / hi widened by kScalarExactMargin so
// that they bound the exact values too (promises hold for a decoder computing in
// double). Exact zeros (the 3-colour black) stay exact.
void scalar_interval_palette(const ScalarTables& T, uint16_t c0, uint16_t c1, Palette<1>& p);

} // namespace atlas::compress::detail

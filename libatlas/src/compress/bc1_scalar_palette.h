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
};

// Tables for an unpack (weights and decoder set). Those of bc1_scalar_unpack(set)
// are built once per set and shared (immutable after a thread-safe initialisation);
// other weights get tables built into `local`.
const ScalarTables& scalar_tables(const ScalarUnpack& u, std::unique_ptr<ScalarTables>& local);

// Interval palette of (c0, c1): identical values to evaluating each decoder's
// palette and the dot product per entry.
void scalar_interval_palette(const ScalarTables& T, uint16_t c0, uint16_t c1, Palette<1>& p);

} // namespace atlas::compress::detail

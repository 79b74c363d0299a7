// Internal: the BC4 encoder's test hooks (tests/compress/bc4_test.cpp), each in the file whose code it checks.
#pragma once

#include "atlas/compress/block.h"

#include <cstddef>

namespace atlas::compress::detail {

// Test hook (bc4_tables.cpp): builds an encoder's tables for (snorm, set) and returns how many
// entries of the 65,536 pair palettes differ (bitwise) from the palettes fast / normal
// assemble from the per-entry tables; 0 when they are the same floats.
long bc4_entry_table_mismatches(bool snorm, DecoderSet set);

// Test hook (bc4_avx2.cpp): for each block (texels finite, within +-2, none -0.0), the level
// pair (lo, hi)'s line-palette evaluations (8-value and 6-value mode) against the full
// evaluation and exact pass of the same pairs' palettes: keys, key max and sum, exact max
// error, squared error, index field, endpoints_only; and that six_may_tie skips only
// 6-value pairs whose evaluation against the 8-value result returns false. Returns the
// number of differences (0 also without AVX2, where there is no line path).
long bc4_line_mismatches(bool snorm, const float* blocks, size_t count, int lo, int hi);

// Test hook (bc4_search.cpp): of `count` blocks (16 texels each), how many an encoder with these options
// encodes differently (bytes or result) with its same-bytes shortcuts (the flat-block
// table, skipping a candidate that cannot win) than without them; 0 when they only save
// time.
long bc4_shortcut_mismatches(bool snorm, const BlockOptions& options, const float* blocks, size_t count);

} // namespace atlas::compress::detail

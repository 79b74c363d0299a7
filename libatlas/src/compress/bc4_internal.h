// Internal: what the BC4 source files share: the encoder's tables (PairTables), their small readers, encode's dispatch.
//
// bc4_decode.cpp: the decoder models and the decoder-set interval (interval_palette).
// bc4_tables.cpp: build_tables, fill_tables, the shared tables and Bc4Encoder's constructor.
// bc4_search.cpp: encode_candidates, the exhaustive search, Bc4Encoder's encode functions.
// bc4_avx2.cpp: the level-pair path (functions compiled for AVX2 by attribute, run after
// the CPU check in fill_tables).
#pragma once

#include "atlas/compress/bc4.h"

#include "bc4_eval.h"
#include "palette_search.h"

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <vector>

namespace atlas::compress {

namespace detail::bc4 {

// Endpoint byte -> integer level (-127..127 for SNORM, -128 reads as -127).
inline int level(uint8_t b, bool snorm) {
    if (!snorm) return b;
    int v = static_cast<int8_t>(b);
    return v < -127 ? -127 : v;
}

// `exact_bounds`: lo / hi bound the exact values (the encoder's tables, so that its
// one-sided and max-error results hold in exact arithmetic); off for the public
// interval decode, which reports the float values the decoder models compute (bc4_decode.cpp).
void interval_palette(uint8_t b0, uint8_t b1, bool snorm, DecoderSet set, detail::Palette<1>& p, bool exact_bounds = false);

inline void write_block_bits(uint8_t b0, uint8_t b1, uint64_t bits, uint8_t out[8]) {
    // One 8-byte store, little-endian: b0, b1, then the 48 index bits from the lowest.
    uint8_t block[8] = {b0, b1};
    for (int i = 0; i < 6; ++i) block[2 + i] = uint8_t(bits >> (8 * i));
    std::memcpy(out, block, 8);
}

inline void write_block(uint8_t b0, uint8_t b1, const uint8_t idx[16], uint8_t out[8]) {
    uint64_t bits = 0;
    for (int t = 0; t < 16; ++t) bits |= uint64_t(idx[t] & 7) << (3 * t);
    write_block_bits(b0, b1, bits, out);
}

struct PairTables {
    std::vector<detail::Palette<1>> pal; // index b0 * 256 + b1
    std::vector<float> pal_min;          // min lo over all entries (one-sided feasibility)
    // Range [imin, imax] of the entries other than the 6-value mode's exact constants
    // (lower bounds), whether the pair is in that mode, and per row b0 and mode the
    // extremes of those ranges (whole rows are skipped).
    std::vector<float> imin, imax;
    std::vector<uint8_t> six;
    std::vector<float> six_mask; // all bits set where six (SIMD blend)
    std::vector<float> ent_lo[8], ent_hi[8]; // entry i of every pair, pair-contiguous (SIMD probes)
    float row_imin[256][2], row_imax[256][2];
    float c_lo = 0, c_hi = 1; // the 6-value mode's constants
    // Spacing bound (search_all_pairs): the exact value of each endpoint byte, and the
    // largest |c - x_j| - h of any entry (interval centre c, half-width h over the
    // decoder set) against the exact, evenly spaced value x_j = lower + j (upper -
    // lower) / steps of its mode, over every pair.
    float val[256];
    double slack[2] = {-1, -1}; // [0]: 8-value mode, [1]: 6-value mode (may be < 0)
    // Every palette entry's interval depends only on its numerator: an endpoint on its
    // byte, an interpolated entry of mode m (0: 8 values, steps 7; 1: 6 values, steps 5)
    // on num = (steps - 1 - k) e0 + (k + 1) e1. These tables (a few KB, cache resident)
    // hold the same floats as `pal` and build fast/normal's candidate palettes, which
    // would otherwise be an L3 or memory miss per candidate.
    float end_lo[256], end_hi[256], end_ref[256];
    std::vector<float> num_lo[2], num_hi[2], num_ref[2];
    // The Reference decoder alone: the same floats as records {lo, hi, ref, 0} per
    // numerator, so that line_palette loads an entry's three with one load.
    std::vector<float> num_record[2];
    float grid_per[2][256] = {}; // the same: steps * scale / d, grid steps per unit value by level spread d
    int num_base[2] = {0, 0}; // index = num - num_base
    bool avx2 = false;        // fast / normal evaluate with AVX2 (same results, bc4_eval.h)
    // fast / normal's results for flat blocks on a level: 16 texels with the bits of
    // level L's float L / scale (8-bit sources; maps clamped at 0 or 1), at L - the
    // lowest level. Filled by fill_tables with encode's own results, so a hit writes
    // the same bytes as the candidate search it replaces (36 ns -> 6 ns a block here).
    bool flat_ready = false;
    bool shortcuts = true; // the flat table and endpoints_only's skip (off: tests' reference)
    float flat_src[256];
    uint8_t flat_out[256][8];
    BlockResult flat_res[256];
};

// Every pair's palette and the search's tables for a decoder set (bc4_tables.cpp).
void build_tables(PairTables& T, bool snorm, DecoderSet decoders);

// An encoder's tables for its options (build_tables, the CPU check, the flat table of
// encode_block's own results; bc4_tables.cpp).
void fill_tables(PairTables& T, bool snorm, const BlockOptions& options);

// An encoder's options: decoders 0 stands for the Reference decoder alone.
inline BlockOptions encoder_options(BlockOptions o) {
    if (o.decoders == 0) o.decoders = kReferenceOnly;
    return o;
}

// fast / normal's candidate palette of pair k from the per-entry tables: the same
// floats as T.pal[k] (test Bc4Eval.EntryTablesEqualPairTables).
inline void entry_palette(const PairTables& T, int k, bool snorm, detail::Palette<1>& p) {
    const uint8_t b0 = uint8_t(k >> 8), b1 = uint8_t(k & 255);
    const int e0 = level(b0, snorm), e1 = level(b1, snorm);
    const bool eight = snorm ? (static_cast<int8_t>(b0) > static_cast<int8_t>(b1)) : (b0 > b1);
    p.n = 8;
    p.lo[0][0] = T.end_lo[b0]; p.hi[0][0] = T.end_hi[b0]; p.ref[0][0] = T.end_ref[b0];
    p.lo[1][0] = T.end_lo[b1]; p.hi[1][0] = T.end_hi[b1]; p.ref[1][0] = T.end_ref[b1];
    const int m = eight ? 0 : 1, steps = eight ? 7 : 5, interp = eight ? 8 : 6;
    const float* lo = T.num_lo[m].data() - T.num_base[m];
    const float* hi = T.num_hi[m].data() - T.num_base[m];
    const float* ref = T.num_ref[m].data() - T.num_base[m];
    for (int i = 2; i < interp; ++i) {
        const int num = (steps - i + 1) * e0 + (i - 1) * e1;
        p.lo[i][0] = lo[num]; p.hi[i][0] = hi[num]; p.ref[i][0] = ref[num];
    }
    if (!eight) {
        p.lo[6][0] = p.hi[6][0] = p.ref[6][0] = T.c_lo;
        p.lo[7][0] = p.hi[7][0] = p.ref[7][0] = 1.0f;
    }
}

// The 6-value pair (L, H) after the 8-value incumbent (H, L) whose every texel took an
// endpoint (index 0 or 1), under narrow intervals (the Reference decoder alone), with
// the texels within [L, H]: the 6-value pair cannot win, so it is not evaluated. Its
// endpoints are the same bytes, so the same intervals and per-texel errors there; each
// texel is within (H - L) / 14 (+ ulps) of its endpoint (the 8 entries' nearest), its
// interpolated entries are at least (H - L) / 5 from both endpoints, and its constants 0
// and 1 (SNORM -1, 1) lie beyond L and H. So every texel's key error is at least the
// incumbent's, and so are the max and the sum (in the same order): no strict improvement.
// (On 8-bit images most blocks two levels wide end here: 12,400 of the cloud render's
// 16,000 non-flat blocks evaluated the 6-value pair in full to tie and lose.)
inline int swapped(int k) { return ((k & 255) << 8) | (k >> 8); }
inline bool endpoints_only(const detail::Bc4Keys& keys) {
    uint32_t any = 0;
    for (int t = 0; t < 16; ++t) any |= keys.key[t] & 6u; // index 0 or 1: bits 1 and 2 clear
    return any == 0;
}

// A flat block on a level, from the table (its float must have the level's bits).
inline bool flat_from_table(const PairTables& T, float v, bool snorm, uint8_t out[8], BlockResult& r) {
    const float scale = snorm ? 127.0f : 255.0f;
    const int lo_lim = snorm ? -127 : 0, hi_lim = snorm ? 127 : 255;
    const float x = v * scale;
    if (!(x >= float(lo_lim) && x <= float(hi_lim))) return false; // finite, so the rounding below is defined
    const int i = int(x + (x >= 0 ? 0.5f : -0.5f)) - lo_lim;
    if (std::memcmp(&v, &T.flat_src[i], 4) != 0) return false;
    std::memcpy(out, T.flat_out[i], 8);
    r = T.flat_res[i];
    return true;
}

// encode's candidate search for any block (the level-pair path aside), apart so that
// encode's level-pair path does not pay this function's frame (bc4_search.cpp).
BlockResult encode_candidates(const PairTables& T, bool snorm, const BlockOptions& options, const float src[16], uint8_t out[8]);

#if defined(ATLAS_BC4_AVX2)
// The level-pair path (bc4_avx2.cpp): encode's for one block (false: the block is left to
// encode_candidates) and encode_blocks' for a run, to encode_candidates' results.
__attribute__((target("avx2"))) bool level_pair_block(const PairTables& T, const float src[16], bool snorm, bool with_six, float bound,
                                                     uint8_t out[8], BlockResult& res);
__attribute__((target("avx2"))) void level_pair_blocks(const PairTables& T, bool snorm, const BlockOptions& options, const float* src,
                                                      size_t count, uint8_t* out, BlockResult* res);

// Where level_pair_blocks applies (the CPU and the options; a block's kind aside).
inline bool level_pairs_apply(const PairTables& T, const BlockOptions& o) {
    return T.avx2 && T.shortcuts && o.decoders == kReferenceOnly && !o.one_sided_below && o.quality != Quality::Best;
}
#endif

// Bc4Encoder::encode and encode_blocks on the tables T (inline: the members are these calls).
inline BlockResult encode_block(const PairTables& T, bool snorm, const BlockOptions& options, const float src[16], uint8_t out[8]) {
#if defined(ATLAS_BC4_AVX2)
    BlockResult r;
    if (level_pairs_apply(T, options) && level_pair_block(T, src, snorm, options.quality != Quality::Fast, options.max_error, out, r))
        return r;
#endif
    return encode_candidates(T, snorm, options, src, out);
}

inline void encode_blocks(const PairTables& T, bool snorm, const BlockOptions& options, const float* src, size_t count, uint8_t* out,
                          BlockResult* results) {
#if defined(ATLAS_BC4_AVX2)
    // Level pairs (8-bit sources: nearly every block not flat) take the same candidates
    // and give the same result through their line palettes (bc4_eval.h).
    if (level_pairs_apply(T, options)) {
        level_pair_blocks(T, snorm, options, src, count, out, results);
        return;
    }
#endif
    for (size_t b = 0; b < count; ++b) results[b] = encode_candidates(T, snorm, options, src + 16 * b, out + 8 * b);
}

} // namespace detail::bc4

struct Bc4Encoder::Tables : detail::bc4::PairTables {};

} // namespace atlas::compress

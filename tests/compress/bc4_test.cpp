// BC4: bounds hold under every decoder model, one-sided holds, exhaustive search is optimal.
#include "atlas/compress/bc4.h"

#include "test_blocks.h"
#include "../../libatlas/src/compress/bc4_eval.h"       // internal: the fast / normal evaluation paths
#include "../../libatlas/src/compress/bc4_test_hooks.h" // internal: the encoder's test hooks

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

namespace atlas::compress {
namespace {

using test::kRandomBlocks;
using test::scalar_block;

// Independent check of one encoded block: decode with each model, compare to the source.
struct Check {
    float max_err = 0;      // max over decoders (Conformant: reference +- tolerance on interpolants)
    float max_over = -1e9f; // max over decoders of decoded - source
    double ref_sq = 0;
};

Check check_block(const uint8_t blk[8], bool snorm, DecoderSet set, const float src[16]) {
    Check c;
    for (Decoder d : decoders_in(set)) {
        float v[16];
        decode_bc4_block(blk, snorm, d, v);
        const bool eight = snorm ? int8_t(blk[0]) > int8_t(blk[1]) : blk[0] > blk[1];
        uint64_t bits = 0;
        for (int i = 0; i < 6; ++i) bits |= uint64_t(blk[2 + i]) << (8 * i);
        for (int t = 0; t < 16; ++t) {
            const int idx = int((bits >> (3 * t)) & 7);
            const bool interp = idx >= 2 && idx < (eight ? 8 : 6);
            const float tol = (d == Decoder::Conformant && interp) ? kConformantTolerance : 0.0f;
            c.max_err = std::max(c.max_err, std::fabs(v[t] - src[t]) + tol);
            c.max_over = std::max(c.max_over, v[t] + tol - src[t]);
            if (d == Decoder::Reference) c.ref_sq += double(v[t] - src[t]) * double(v[t] - src[t]);
        }
    }
    return c;
}

void run_random(bool snorm, bool one_sided, Quality q, DecoderSet set, int blocks) {
    BlockOptions o;
    o.quality = q;
    o.one_sided_below = one_sided;
    o.decoders = set;
    Bc4Encoder enc(snorm, o);
    double under = 0;
    for (int k = 0; k < blocks; ++k) {
        float src[16];
        scalar_block(uint64_t(k) + (snorm ? 77777 : 0), snorm ? -1.0f : 0.0f, 1.0f, src);
        uint8_t blk[8];
        BlockResult r = enc.encode(src, blk);
        Check c = check_block(blk, snorm, set | kReferenceOnly, src);
        ASSERT_LE(c.max_err, r.max_error + 1e-6f) << "block " << k;
        ASSERT_NEAR(c.ref_sq, r.sum_sq, 1e-6 + 1e-6 * r.sum_sq) << "block " << k;
        if (one_sided) { ASSERT_LE(c.max_over, 0.0f) << "block " << k; }
        under += r.sum_sq;
    }
    (void)under;
}

// fast / normal assemble each candidate palette from per-entry tables (a few KB) instead
// of the 65,536-pair table: the same floats for every pair, mode, decoder set, UNORM / SNORM.
TEST(Bc4Eval, EntryTablesEqualPairTables) {
    for (bool snorm : {false, true})
        for (DecoderSet set : {kReferenceOnly, kAllDecoders, decoder_bit(Decoder::Tool8) | decoder_bit(Decoder::Tool8Round),
                               decoder_bit(Decoder::Conformant)})
            EXPECT_EQ(detail::bc4_entry_table_mismatches(snorm, set), 0) << "snorm " << snorm << " set " << set;
}

// A palette of 8 random intervals (lo <= ref <= hi), sorted or not, wide or a few ulps.
void random_palette(uint64_t k, detail::Palette<1>& p) {
    p.n = 8;
    const bool narrow = k % 3 != 0, sorted = k % 2 == 0;
    for (int i = 0; i < 8; ++i) {
        float c = float(test::unit(k, 100 + uint64_t(i)));
        if (sorted) c = float((i + test::unit(k, 100 + uint64_t(i))) / 8.0);
        const float w = narrow ? c * 1e-7f * float(i % 3) : float(test::unit(k, 200 + uint64_t(i))) * (2.0f / 255.0f);
        p.lo[i][0] = c - w;
        p.hi[i][0] = c + w;
        p.ref[i][0] = c;
    }
    if (k % 5 == 0) { p.lo[6][0] = p.hi[6][0] = p.ref[6][0] = 0.0f; p.lo[7][0] = p.hi[7][0] = p.ref[7][0] = 1.0f; }
}

template <bool OS>
void expect_paths_equal(const detail::Palette<1>& p, const float* src, float stop, float inc_sum, uint64_t k) {
    detail::Bc4Keys a, b;
    const bool ra = detail::bc4_keys_portable<OS>(p, src, stop, inc_sum, a);
#if defined(__SSE2__)
    const bool rb = detail::bc4_keys_sse2<OS>(p, src, stop, inc_sum, b);
#else
    const bool rb = detail::bc4_keys_portable<OS>(p, src, stop, inc_sum, b);
#endif
    ASSERT_EQ(ra, rb) << "case " << k;
#if defined(ATLAS_BC4_AVX2)
    if (detail::bc4_cpu_has_avx2()) {
        detail::Bc4Keys c;
        ASSERT_EQ(detail::bc4_keys_avx2<OS>(p, src, stop, inc_sum, c), ra) << "case " << k;
        if (ra) {
            ASSERT_EQ(std::memcmp(&a.max_err, &c.max_err, 4), 0) << "case " << k;
            ASSERT_EQ(std::memcmp(&a.sum, &c.sum, 4), 0) << "case " << k;
            ASSERT_EQ(std::memcmp(a.key, c.key, sizeof a.key), 0) << "case " << k;
            float m0, m1;
            double q0, q1;
            uint64_t i0, i1;
            detail::bc4_exact_portable<OS>(p, src, a, m0, q0, i0);
            detail::bc4_exact_avx2(p, src, a, m1, q1, i1);
            ASSERT_EQ(std::memcmp(&m0, &m1, 4), 0) << "case " << k;
            ASSERT_EQ(std::memcmp(&q0, &q1, 8), 0) << "case " << k;
            ASSERT_EQ(i0, i1) << "case " << k;
        }
    }
#endif
    bool all_same = true;
    for (int t = 1; t < 16; ++t) all_same = all_same && std::memcmp(&src[t], &src[0], 4) == 0;
    if (all_same) {
        detail::Bc4Keys f;
        ASSERT_EQ(detail::bc4_keys_flat<OS>(p, src, stop, inc_sum, f), ra) << "case " << k;
        if (ra) {
            ASSERT_EQ(std::memcmp(&a.max_err, &f.max_err, 4), 0) << "case " << k;
            ASSERT_EQ(std::memcmp(&a.sum, &f.sum, 4), 0) << "case " << k;
            ASSERT_EQ(std::memcmp(a.key, f.key, sizeof a.key), 0) << "case " << k;
            float m0, m1;
            double q0, q1;
            uint64_t b0, b1;
            detail::bc4_exact_portable<OS>(p, src, a, m0, q0, b0);
            detail::bc4_exact_flat<OS>(p, src, a, m1, q1, b1);
            ASSERT_EQ(std::memcmp(&m0, &m1, 4), 0) << "case " << k;
            ASSERT_EQ(std::memcmp(&q0, &q1, 8), 0) << "case " << k;
            ASSERT_EQ(b0, b1) << "case " << k;
        }
    }
    if (!ra) return;
    ASSERT_EQ(std::memcmp(&a.max_err, &b.max_err, 4), 0) << "case " << k;
    ASSERT_EQ(std::memcmp(&a.sum, &b.sum, 4), 0) << "case " << k;
    ASSERT_EQ(std::memcmp(a.key, b.key, sizeof a.key), 0) << "case " << k;
    // The exact pass: the chosen entries' max error and squared Reference error, recomputed here.
    float m;
    double q;
    uint64_t bits;
    detail::bc4_exact_portable<OS>(p, src, a, m, q, bits);
    float m_ref = 0;
    double q_ref = 0;
    for (int t = 0; t < 16; ++t) {
        const int i = int((bits >> (3 * t)) & 7);
        ASSERT_EQ(i, int(a.key[t] & 7u)) << "case " << k;
        m_ref = std::max(m_ref, detail::entry_error_t<1, OS>(p, i, src + t));
        q_ref += (double(p.ref[i][0]) - src[t]) * (double(p.ref[i][0]) - src[t]);
    }
    ASSERT_EQ(m, m_ref) << "case " << k;
    ASSERT_NEAR(q, q_ref, 1e-12 * (1 + q_ref)) << "case " << k;
    // Each texel's key is its least error (to the 3 dropped bits) and names its entry.
    for (int t = 0; t < 16; ++t) {
        float best = INFINITY;
        for (int i = 0; i < 8; ++i) best = std::min(best, detail::entry_error_t<1, OS>(p, i, src + t));
        const int i = int(a.key[t] & 7u);
        const float e = detail::entry_error_t<1, OS>(p, i, src + t);
        ASSERT_LE(detail::bc4_key_error(a.key[t]), e) << "case " << k;
        ASSERT_LE(e, best * (1.0f + 1e-6f)) << "case " << k << " texel " << t;
    }
}

// The SSE2, AVX2 (where the CPU has it) and flat-block (16 equal texels) key evaluations
// return the same keys, maxima and sums as the portable one, and the AVX2 exact pass the
// same errors, squared errors and indices.
TEST(Bc4Eval, Sse2EqualsPortable) {
    for (uint64_t k = 0; k < uint64_t(test::kRandomBlocks / 10); ++k) {
        detail::Palette<1> p;
        random_palette(k, p);
        float src[16];
        test::scalar_block(k, 0.0f, 1.0f, src);
        const float stop = k % 4 == 0 ? float(test::unit(k, 7)) * 0.05f : detail::kBc4Infeasible;
        expect_paths_equal<false>(p, src, stop, INFINITY, k);
        expect_paths_equal<true>(p, src, stop, INFINITY, k);
        // An incumbent tied with the candidate's own max error: the sum decides (below, equal, above).
        for (bool os : {false, true}) {
            detail::Bc4Keys own;
            const bool ok = os ? detail::bc4_keys_portable<true>(p, src, detail::kBc4Infeasible, INFINITY, own)
                               : detail::bc4_keys_portable<false>(p, src, detail::kBc4Infeasible, INFINITY, own);
            if (!ok) continue;
            for (float f : {0.5f, 1.0f, 2.0f}) {
                if (os) expect_paths_equal<true>(p, src, own.max_err, own.sum * f, k);
                else expect_paths_equal<false>(p, src, own.max_err, own.sum * f, k);
            }
            detail::Bc4Keys tied;
            const bool r = os ? detail::bc4_keys_portable<true>(p, src, own.max_err, own.sum, tied)
                              : detail::bc4_keys_portable<false>(p, src, own.max_err, own.sum, tied);
            EXPECT_EQ(r, false) << "case " << k << ": a tie with an equal sum cannot win";
        }
    }
}

// A level pair's palette values under the Reference decoder, from the public decoder:
// v[i] for index i of the block (b0, b1).
void reference_palette(uint8_t b0, uint8_t b1, bool snorm, float v[8]) {
    for (int i = 0; i < 8; ++i) {
        const uint64_t bits = uint64_t(i) * 0x249249249249ull; // i in all 16 fields
        uint8_t blk[8] = {b0, b1, 0, 0, 0, 0, 0, 0};
        for (int j = 0; j < 6; ++j) blk[2 + j] = uint8_t(bits >> (8 * j));
        float out[16];
        decode_bc4_block(blk, snorm, Decoder::Reference, out);
        v[i] = out[0];
    }
}

// The level-pair path (8-bit-like blocks: texels whose extremes are levels lo < hi) finds
// each texel's least key among the two palette entries around it instead of all 8; it
// must give the full evaluation's keys, sums, exact errors and indices for any texel
// within +-2. The hard texels: on a palette value, at the midpoint of two, each nudged by
// up to 8 ulps (the keys resolve ties to 8 ulps), beyond the palette's ends, on the levels.
TEST(Bc4Eval, LineKeysEqualFullKeys) {
    if (!detail::bc4_cpu_has_avx2()) GTEST_SKIP() << "no AVX2: the level-pair path is not used";
    for (bool snorm : {false, true}) {
        const float scale = snorm ? 127.0f : 255.0f;
        const int lmin = snorm ? -127 : 0, lmax = snorm ? 127 : 255;
        auto byte_of = [&](int v) { return uint8_t(snorm ? uint8_t(int8_t(v)) : uint8_t(v)); };
        std::vector<std::pair<int, int>> pairs = {{lmin, lmin + 1}, {lmin, lmax}, {lmax - 1, lmax}, {lmin, lmin + 2}, {lmin + 3, lmin + 8}, {0, 7}, {0, 5}};
        if (snorm) pairs.insert(pairs.end(), {{-1, 1}, {-127, 0}, {0, 127}});
        for (uint64_t k = 0; k < 40; ++k) {
            const int lo = lmin + int(test::unit(k + (snorm ? 500 : 0), 1) * (lmax - lmin));
            const int span = 1 + int(test::unit(k + (snorm ? 500 : 0), 2) * (k % 3 == 0 ? 12 : lmax - lo));
            pairs.push_back({lo, std::min(lmax, lo + span)});
        }
        for (const auto& [lo, hi] : pairs) {
            if (!(lo < hi)) continue;
            std::vector<float> special; // palette values and midpoints of both modes
            for (int m = 0; m < 2; ++m) {
                float v[8];
                reference_palette(m == 0 ? byte_of(hi) : byte_of(lo), m == 0 ? byte_of(lo) : byte_of(hi), snorm, v);
                std::sort(v, v + 8);
                for (int i = 0; i < 8; ++i) {
                    special.push_back(v[i]);
                    if (i + 1 < 8) special.push_back(0.5f * (v[i] + v[i + 1]));
                }
            }
            std::vector<float> blocks;
            for (uint64_t b = 0; b < 64; ++b)
                for (int t = 0; t < 16; ++t) {
                    const uint64_t seed = uint64_t(lo * 1000 + hi) * 131 + b + (snorm ? 1u << 20 : 0);
                    const double u = test::unit(seed, uint64_t(t) + 1), w = test::unit(seed, uint64_t(t) + 100);
                    float x;
                    switch (int(u * 5)) {
                    case 0:
                    case 1: { // a palette value or midpoint, nudged by -8..8 ulps
                        x = special[size_t(w * double(special.size())) % special.size()];
                        const int nudge = int(test::unit(seed, uint64_t(t) + 200) * 17) - 8;
                        for (int j = 0; j < std::abs(nudge); ++j) x = std::nextafter(x, nudge > 0 ? 2.0f : -2.0f);
                        break;
                    }
                    case 2: x = float((lo - 2 + w * (hi - lo + 4)) / scale); break;              // around the pair
                    case 3: x = float(-2.0 + 4.0 * w); break;                                     // anywhere within +-2
                    default: x = float(lo + int(w * (hi - lo + 1))) / scale; break;               // on the levels
                    }
                    blocks.push_back(x == 0.0f ? 0.0f : x); // -0.0 takes the full path (bc4_avx2.cpp)
                }
            EXPECT_EQ(detail::bc4_line_mismatches(snorm, blocks.data(), blocks.size() / 16, lo, hi), 0)
                << (snorm ? "snorm" : "unorm") << " pair " << lo << ", " << hi;
        }
    }
}

TEST(Bc4, RandomBlocksUnormAllDecoders) { run_random(false, false, Quality::Normal, kAllDecoders, kRandomBlocks); }
TEST(Bc4, RandomBlocksSnormAllDecoders) { run_random(true, false, Quality::Normal, kAllDecoders, kRandomBlocks); }
TEST(Bc4, RandomBlocksOneSidedEveryDecoder) { run_random(false, true, Quality::Normal, kAllDecoders, kRandomBlocks); }
TEST(Bc4, RandomBlocksOneSidedFast) { run_random(false, true, Quality::Fast, kAllDecoders, kRandomBlocks / 4); }

TEST(Bc4, MaxErrorIsMetOrProvablyUnreachable) {
    BlockOptions o;
    o.max_error = 1.0f / 255.0f;
    o.decoders = kAllDecoders;
    Bc4Encoder enc(false, o);
    BlockOptions ob = o;
    ob.quality = Quality::Best;
    Bc4Encoder best(false, ob);
    int missed = 0;
    for (int k = 0; k < 2000 / test::kExhaustiveDivisor; ++k) {
        float src[16];
        scalar_block(uint64_t(k) + 5, 0, 1, src);
        uint8_t a[8], b[8];
        BlockResult r = enc.encode(src, a);
        if (r.max_error > o.max_error) {
            ++missed;
            BlockResult rb = best.encode(src, b);
            EXPECT_EQ(rb.max_error, r.max_error) << "a missed block must be the exhaustive optimum";
        }
    }
    EXPECT_GT(missed, 0); // noise blocks cannot reach 1/255 under every decoder
}

// Naive optimum with the Reference decoder only: all pairs, best index per texel.
float naive_best(const float src[16], bool one_sided) {
    float best = INFINITY;
    for (int k = 0; k < 65536; ++k) {
        uint8_t blk[8] = {uint8_t(k >> 8), uint8_t(k & 255), 0, 0, 0, 0, 0, 0};
        float pal[8];
        for (int i = 0; i < 8; ++i) { // decode each index through the public decoder
            uint64_t bits = 0;
            for (int t = 0; t < 16; ++t) bits |= uint64_t(i) << (3 * t);
            for (int j = 0; j < 6; ++j) blk[2 + j] = uint8_t(bits >> (8 * j));
            float v[16];
            decode_bc4_block(blk, false, Decoder::Reference, v);
            pal[i] = v[0];
        }
        float worst = 0;
        for (int t = 0; t < 16 && worst < best; ++t) {
            float e = INFINITY;
            for (float p : pal)
                if (!one_sided || p <= src[t]) e = std::min(e, std::fabs(p - src[t]));
            worst = std::max(worst, e);
        }
        best = std::min(best, worst);
    }
    return best;
}

TEST(Bc4, BestIsOptimalAgainstNaiveSearch) {
    for (bool os : {false, true}) {
        BlockOptions o;
        o.quality = Quality::Best;
        o.decoders = kReferenceOnly;
        o.one_sided_below = os;
        Bc4Encoder enc(false, o);
        for (int k = 0; k < std::max(1, 6 / test::kExhaustiveDivisor); ++k) {
            float src[16];
            scalar_block(uint64_t(k) * 7 + 3, 0, 1, src);
            uint8_t blk[8];
            BlockResult r = enc.encode(src, blk);
            EXPECT_FLOAT_EQ(r.max_error, naive_best(src, os)) << "block " << k << " one-sided " << os;
        }
    }
}

// The exhaustive search started from the normal candidates' incumbent (Best, and blocks
// missing max_error) must write the very block a search from scratch writes: the
// pruning bounds are true lower bounds and exact ties go to the lowest pair index.
TEST(Bc4, SeededExhaustiveSearchEqualsSearchFromScratch) {
    for (bool snorm : {false, true})
        for (bool os : {false, true})
            for (DecoderSet set : {kReferenceOnly, kAllDecoders}) {
                BlockOptions o;
                o.quality = Quality::Best;
                o.one_sided_below = os;
                o.decoders = set;
                Bc4Encoder best(snorm, o);
                BlockOptions ob = o;
                ob.quality = Quality::Normal;
                ob.max_error = 0.0f; // every non-exact block falls back to the exhaustive search
                Bc4Encoder bounded(snorm, ob);
                for (int k = 0; k < std::max(2, 120 / test::kExhaustiveDivisor); ++k) {
                    float src[16];
                    scalar_block(uint64_t(k) * 13 + 11, snorm ? -1.0f : 0.0f, 1.0f, src);
                    uint8_t a[8], b[8], c[8];
                    const BlockResult ra = best.encode(src, a);
                    const BlockResult rb = best.encode_exhaustive(src, b);
                    const BlockResult rc = bounded.encode(src, c);
                    EXPECT_EQ(0, std::memcmp(a, b, 8)) << "block " << k << " snorm " << snorm << " one-sided " << os;
                    EXPECT_EQ(ra.max_error, rb.max_error);
                    EXPECT_EQ(ra.sum_sq, rb.sum_sq);
                    if (rc.max_error > 0.0f) { // missed the bound: the exhaustive optimum
                        EXPECT_EQ(0, std::memcmp(c, b, 8)) << "block " << k;
                        EXPECT_EQ(rc.max_error, rb.max_error);
                    }
                }
            }
}

// Flat blocks under fast (which tries their 6-value pair: the 8-value pair needs e0 > e1)
// decode exactly to a representable level.
TEST(Bc4, FastEncodesFlatBlocksWithTheirLevel) {
    BlockOptions o;
    o.quality = Quality::Fast;
    o.decoders = kReferenceOnly;
    Bc4Encoder fast(false, o);
    for (int level : {0, 1, 77, 128, 254, 255}) {
        float src[16];
        std::fill(src, src + 16, float(level) / 255.0f);
        uint8_t blk[8];
        const BlockResult r = fast.encode(src, blk);
        // The reported error bounds the exact one: float(level / 255) is an ulp away from
        // level / 255 (except 0 and 1), and the bound is widened by 2^-21 relative.
        EXPECT_LE(r.max_error, src[0] * 1.0e-6f) << "level " << level;
        if (level == 0 || level == 255) {
            EXPECT_EQ(r.max_error, 0.0f);
        }
        float v[16];
        decode_bc4_block(blk, false, Decoder::Reference, v);
        for (int t = 0; t < 16; ++t) EXPECT_EQ(v[t], src[t]);
    }
}

TEST(Bc4, NormalNeverBeatsBest) {
    BlockOptions o;
    Bc4Encoder normal(false, o);
    o.quality = Quality::Best;
    Bc4Encoder best(false, o);
    for (int k = 0; k < 300 / test::kExhaustiveDivisor; ++k) {
        float src[16];
        scalar_block(uint64_t(k) + 900, 0, 1, src);
        uint8_t a[8], b[8];
        EXPECT_LE(best.encode(src, b).max_error, normal.encode(src, a).max_error);
    }
}

TEST(Bc4, ConstantAndExtremeBlocksAreExact) {
    BlockOptions o;
    o.decoders = kAllDecoders;
    Bc4Encoder enc(false, o);
    for (float v : {0.0f, 1.0f, 128.0f / 255.0f}) {
        float src[16];
        std::fill(src, src + 16, v);
        uint8_t blk[8];
        const float e = enc.encode(src, blk).max_error;
        if (v == 0.0f || v == 1.0f) {
            EXPECT_EQ(e, 0.0f);
        } else {
            EXPECT_LE(e, v * 1.0e-6f) << v; // an exact-arithmetic bound (see FastEncodesFlatBlocksWithTheirLevel)
        }
        float dec[16];
        decode_bc4_block(blk, false, Decoder::Reference, dec);
        for (int t = 0; t < 16; ++t) EXPECT_EQ(dec[t], v);
    }
    float two[16];
    for (int t = 0; t < 16; ++t) two[t] = (t & 1) ? 1.0f : 0.0f;
    uint8_t blk[8];
    EXPECT_EQ(enc.encode(two, blk).max_error, 0.0f);
}

TEST(Bc4, SnormMinus128ReadsAsMinus127) {
    uint8_t a[8] = {0x80, 0, 0, 0, 0, 0, 0, 0}, b[8] = {0x81, 0, 0, 0, 0, 0, 0, 0};
    float va[16], vb[16];
    decode_bc4_block(a, true, Decoder::Reference, va);
    decode_bc4_block(b, true, Decoder::Reference, vb);
    EXPECT_EQ(va[0], -1.0f);
    EXPECT_EQ(vb[0], -1.0f);
}

TEST(Bc4, Tool8TruncatesWhereReferenceDoesNot) {
    // e0 = 255, e1 = 0 (8-value mode), index 2 = 6/7 * 255 = 218.57: tool decoders give 218.
    uint8_t blk[8] = {255, 0, 2, 0, 0, 0, 0, 0};
    float ref[16], tool[16];
    decode_bc4_block(blk, false, Decoder::Reference, ref);
    decode_bc4_block(blk, false, Decoder::Tool8, tool);
    EXPECT_FLOAT_EQ(ref[0], 6.0f / 7.0f);
    EXPECT_FLOAT_EQ(tool[0], 218.0f / 255.0f);
}

} // namespace
} // namespace atlas::compress

namespace atlas::compress {
namespace {

// Brute force over all 65,536 pairs with the public interval decoder (every entry of
// a pair from one decode: texel t uses index t % 8), no pruning: the optimum of the
// worst-case error over the decoder set (one-sided: no entry above the texel).
struct BruteBc4 {
    std::vector<float> lo, hi; // [pair * 8 + entry]
    BruteBc4(bool snorm, DecoderSet set) : lo(65536 * 8), hi(65536 * 8) {
        uint64_t bits = 0;
        for (int t = 0; t < 16; ++t) bits |= uint64_t(t % 8) << (3 * t);
        for (int k = 0; k < 65536; ++k) {
            uint8_t blk[8] = {uint8_t(k >> 8), uint8_t(k & 255)};
            for (int j = 0; j < 6; ++j) blk[2 + j] = uint8_t(bits >> (8 * j));
            float l[16], h[16];
            decode_bc4_interval(blk, snorm, set, l, h);
            for (int i = 0; i < 8; ++i) { lo[size_t(k) * 8 + size_t(i)] = l[i]; hi[size_t(k) * 8 + size_t(i)] = h[i]; }
        }
    }
    float optimum(const float src[16], bool one_sided) const {
        float best = INFINITY;
        for (size_t k = 0; k < 65536; ++k) {
            float worst = 0;
            for (int t = 0; t < 16 && worst < best; ++t) {
                float e = INFINITY;
                for (size_t i = 0; i < 8; ++i) {
                    const float l = lo[k * 8 + i], h = hi[k * 8 + i];
                    if (one_sided && h > src[t]) continue;
                    e = std::min(e, std::max({h - src[t], src[t] - l, 0.0f}));
                }
                worst = std::max(worst, e);
            }
            best = std::min(best, worst);
        }
        return best;
    }
};

// Block k of a stream of real and synthetic data: the mixed random stream, smooth ramps
// of every steepness (where the search's spacing bound prunes most) and 4x4 patches of
// exact distances to spheres at 2-32 m voxels mapped from -256..4096 m (the SDF volumes).
void search_block(uint64_t k, bool snorm, float out[16]) {
    const float lo = snorm ? -1.0f : 0.0f;
    switch (k % 3) {
    case 0: scalar_block(k, lo, 1.0f, out); return;
    case 1: {
        const double base = test::unit(k, 1), slope = std::pow(10.0, -3.0 + 2.7 * test::unit(k, 2)), ang = 6.2832 * test::unit(k, 3);
        for (int t = 0; t < 16; ++t) {
            const double v = base + slope * (std::cos(ang) * (t % 4) + std::sin(ang) * (t / 4));
            out[t] = float(std::clamp(lo + (1.0 - lo) * v, double(lo), 1.0));
        }
        return;
    }
    default: {
        const double voxel = 2.0 * std::pow(2.0, 4.0 * test::unit(k, 4)), r = 50 + 400 * test::unit(k, 5);
        const double cx = 300 * test::unit(k, 6), cy = 300 * test::unit(k, 7), z = 200 * test::unit(k, 8) - 100;
        for (int t = 0; t < 16; ++t) {
            const double x = voxel * (t % 4) - cx, y = voxel * (t / 4) - cy;
            const double d = std::clamp(std::sqrt(x * x + y * y + z * z) - r, -256.0, 4096.0);
            out[t] = float(lo + (1.0 - lo) * (d + 256.0) / 4352.0);
        }
        return;
    }
    }
}

// `best` is the exhaustive optimum: never above the brute force's optimum by more than
// the encoder's exact-arithmetic widening of the decoders' float values (2 ulps at 1.0),
// on random, smooth and SDF blocks, UNORM and SNORM, Reference and all 6 decoders,
// two- and one-sided.
TEST(Bc4, BestEqualsBruteForceOnRandomSmoothAndSdfBlocks) {
    constexpr float kWidening = 2.5e-7f;
    const int blocks = std::max(3, 150 / test::kExhaustiveDivisor);
    for (bool snorm : {false, true})
        for (DecoderSet set : {kReferenceOnly, kAllDecoders}) {
            const BruteBc4 brute(snorm, set);
            for (bool os : {false, true}) {
                BlockOptions o;
                o.quality = Quality::Best;
                o.decoders = set;
                o.one_sided_below = os;
                Bc4Encoder enc(snorm, o);
                for (int k = 0; k < blocks; ++k) {
                    float src[16];
                    search_block(uint64_t(k) * 31 + 5, snorm, src);
                    uint8_t blk[8];
                    const BlockResult r = enc.encode(src, blk);
                    const float opt = brute.optimum(src, os);
                    EXPECT_LE(r.max_error, opt + kWidening) << "block " << k << " snorm " << snorm << " all " << (set == kAllDecoders) << " os " << os;
                    EXPECT_GE(r.max_error, opt - kWidening) << "block " << k; // the brute force is a true optimum too
                }
            }
        }
}

} // namespace
} // namespace atlas::compress

namespace atlas::compress {
namespace {

// The encoder's same-bytes shortcuts change nothing but the time, for UNORM and SNORM, any
// decoder set, one-sided or not, with a bound: flat blocks on a level (8-bit sources, maps
// clamped at 0 or 1) come from a table fast / normal fill with their own search's results;
// the 6-value pair is not evaluated after an 8-value incumbent that used only its
// endpoints (blocks a few levels wide, as 8-bit images have by the thousand) or when its
// texels lie farther from its grid than the incumbent's max error; level pairs (extremes on
// levels) are evaluated on their line palettes; encode_blocks gives encode's results.
TEST(Bc4, ShortcutsEqualTheSearch) {
    for (bool snorm : {false, true}) {
        const float scale = snorm ? 127.0f : 255.0f;
        const int lmin = snorm ? -127 : 0, lmax = snorm ? 127 : 255;
        std::vector<float> blocks;
        for (int l = lmin; l <= lmax; ++l) blocks.insert(blocks.end(), 16, float(l) / scale); // flat on every level
        for (uint64_t k = 0; k < 3000; ++k) { // 1 to 6 levels wide, on the levels; a few off them
            const int width = 1 + int(k % 6), base = lmin + int(test::unit(k, 1) * double(lmax - lmin - width));
            for (int t = 0; t < 16; ++t) {
                const int l = base + int(test::unit(k, 10 + uint64_t(t)) * (width + 1) * 0.999);
                blocks.push_back(k % 7 == 0 ? (float(l) + 0.25f) / scale : float(l) / scale);
            }
        }
        // Level pairs (the extremes on levels lo < hi, up to the whole range) with texels
        // between and on the grids' midpoints; texels beyond the range (clamped to the end
        // levels) and beyond +-2; -0.0 beside 0; NaN and infinity.
        for (uint64_t k = 0; k < 1500; ++k) {
            const int lo = lmin + int(test::unit(k, 3) * (lmax - lmin - 1));
            const int hi = std::min(lmax, lo + 1 + int(test::unit(k, 4) * (k % 2 ? 8 : lmax - lmin)));
            float b[16];
            for (int t = 0; t < 16; ++t) {
                const double w = test::unit(k, 40 + uint64_t(t));
                const int j = int(test::unit(k, 60 + uint64_t(t)) * 14);
                b[t] = t % 3 == 0 ? float((lo + w * (hi - lo)) / scale) : float((lo + (hi - lo) * (j / 14.0)) / scale);
            }
            b[int(k % 16)] = float(lo) / scale;
            b[int((k + 7) % 16)] = float(hi) / scale;
            blocks.insert(blocks.end(), b, b + 16);
        }
        // (-0.0 on levels 0..5, where the 6-value pair wins: its entry 0 and its constant 0
        // tie on the error -0.0, and the keys' order of negative floats picks the constant.)
        const std::vector<std::vector<float>> specials = {{-0.0f, 0.0f, 1.0f / scale, 2.0f / scale},
                                                          {-0.0f, 0.0f, 1.0f / scale, 2.0f / scale, 3.0f / scale, 4.0f / scale, 5.0f / scale, 5.0f / scale},
                                                          {-0.5f, 0.2f, 1.5f, 0.9f},
                                                          {1.9f, 1.99f, 0.5f, -1.9f},
                                                          {3.0f, 0.5f, 0.25f, 0.0f},
                                                          {NAN, 0.5f, 0.25f, 0.0f},
                                                          {INFINITY, 0.5f, 0.25f, 0.0f}};
        for (const auto& sp : specials)
            for (size_t t = 0; t < 16; ++t) blocks.push_back(sp[t % sp.size()]);
        for (Quality q : {Quality::Fast, Quality::Normal})
            for (DecoderSet set : {kReferenceOnly, kAllDecoders})
                for (bool os : {false, true}) {
                    BlockOptions o;
                    o.quality = q;
                    o.decoders = set;
                    o.one_sided_below = os;
                    o.max_error = os ? 0.5f / 255.0f : set == kReferenceOnly ? 3.0f / scale : -1.0f; // blocks missing it take the exhaustive search
                    EXPECT_EQ(detail::bc4_shortcut_mismatches(snorm, o, blocks.data(), blocks.size() / 16), 0)
                        << "snorm " << snorm << " quality " << quality_name(q) << " decoders " << set << " one-sided " << os;
                }
    }
    // A flat block off the levels (and -0.0, whose bits are not level 0's) still
    // searches, and decodes within its reported error.
    Bc4Encoder enc(false, BlockOptions{});
    for (float v : {-0.0f, 0.3f, 100.5f / 255.0f}) {
        float src[16], lo[16], hi[16];
        std::fill(src, src + 16, v);
        uint8_t blk[8];
        const BlockResult r = enc.encode(src, blk);
        decode_bc4_interval(blk, false, kAllDecoders, lo, hi);
        for (int t = 0; t < 16; ++t) EXPECT_LE(std::max(hi[t] - v, v - lo[t]), r.max_error + 1e-7f) << v;
    }
}

} // namespace
} // namespace atlas::compress

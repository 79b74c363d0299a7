// BC4 level-pair path: 8-bit-like blocks on their line palettes, in functions compiled for AVX2 by attribute.
#include "atlas/compress/bc4.h"

#include "bc4_internal.h"
#include "bc4_test_hooks.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>

namespace atlas::compress {

#if defined(ATLAS_BC4_AVX2)
namespace {

using namespace detail::bc4;

// The line palette (bc4_eval.h) of the pair on levels lo < hi: the 8-value mode (hi, lo)
// or the 6-value mode (lo, hi); the Reference decoder alone (build_tables' numerator
// slots at the endpoints). Grid value j has the numerator steps * lo + j (hi - lo).
__attribute__((target("avx2"), always_inline)) inline void line_palette(const PairTables& T, int lo, int hi, bool eight, detail::Bc4LinePalette& p) {
    // 8 values: entry 1 (lo), 7, 6, .., 2, 0 (hi); 6 values: the constant below (6), 0
    // (lo), 2, .., 5, 1 (hi), the constant above (7).
    static constexpr int32_t kIndex[2][8] = {{1, 7, 6, 5, 4, 3, 2, 0}, {6, 0, 2, 3, 4, 5, 1, 7}};
    const int m = eight ? 0 : 1, steps = eight ? 7 : 5;
    const int at = steps * lo - T.num_base[m], d = hi - lo;
    // Grid value j's record at r + j * stride; two records per load (one in each lane),
    // then a 4 x 4 transpose within the lanes gives lo, hi and ref for the 8 positions.
    // The 6-value mode's lanes 0 and 7 (its constants) load a grid end and are replaced.
    const float* r = T.num_record[m].data() + 4 * size_t(at);
    const size_t stride = 4 * size_t(d);
    auto pair_of = [&](int j0, int j1) __attribute__((target("avx2"))) { return _mm256_loadu2_m128(r + size_t(j1) * stride, r + size_t(j0) * stride); };
    const __m256 a0 = eight ? pair_of(0, 4) : pair_of(0, 3), a1 = eight ? pair_of(1, 5) : pair_of(0, 4);
    const __m256 a2 = eight ? pair_of(2, 6) : pair_of(1, 5), a3 = eight ? pair_of(3, 7) : pair_of(2, 5);
    const __m256d t0 = _mm256_castps_pd(_mm256_unpacklo_ps(a0, a1)), t1 = _mm256_castps_pd(_mm256_unpacklo_ps(a2, a3));
    const __m256d t2 = _mm256_castps_pd(_mm256_unpackhi_ps(a0, a1)), t3 = _mm256_castps_pd(_mm256_unpackhi_ps(a2, a3));
    p.lo = _mm256_castpd_ps(_mm256_unpacklo_pd(t0, t1));
    p.hi = _mm256_castpd_ps(_mm256_unpackhi_pd(t0, t1));
    p.ref = _mm256_castpd_ps(_mm256_unpacklo_pd(t2, t3));
    if (!eight) {
        const __m256 constants = _mm256_setr_ps(T.c_lo, 0, 0, 0, 0, 0, 0, T.c_hi);
        p.lo = _mm256_blend_ps(p.lo, constants, 0x81);
        p.hi = _mm256_blend_ps(p.hi, constants, 0x81);
        p.ref = _mm256_blend_ps(p.ref, constants, 0x81);
    }
    p.index = kIndex[m];
    // The exact grid's spacing (no division on the chain; the floats' grid is within
    // ulps of it, and the keys need the position only to within half a step).
    p.origin = r[2];
    p.per_value = T.grid_per[m][d];
    p.offset = (eight ? 0.0f : 1.0f) - p.origin * p.per_value;
}

// Whether the 6-value pair of a level pair can hold every texel within the 8-value
// incumbent's max error E, from the texels' distances to its even grid (the 8-value
// evaluation's six_far: in grid steps, through the 8-value line's position and spacing,
// the same grid value, 5 steps instead of 7). The distance computed so is within ~3e-7
// of the exact one in value (values within +-2), and the 6-value pair's key errors are
// at least the exact distances less 8 ulps (its constants lie on or beyond its grid ends
// and are never nearer than they), so a texel more than E + 1e-5 away fails that pair:
// its evaluation would return false (max error above the incumbent's). On 8-bit sources
// the two modes' errors are multiples of 1/35 level (1.1e-4), so every pair whose max
// error is the larger is skipped here.
__attribute__((target("avx2"), always_inline)) inline bool six_may_tie(const detail::Bc4LinePalette& eight, const detail::Bc4LineResult& r) {
    return !(r.six_far > (r.keys.max_err + 1e-5f) * eight.per_value * (5.0f / 7.0f));
}

// Level pairs: the extremes' floor and ceiling (as encode computes them, clamped to the
// levels) are the levels lo < hi, so the candidate loop's pairs are (hi, lo) then (lo,
// hi) unless fast; the Reference decoder alone, two-sided, finite texels within +-2 and
// none -0.0 (which has the error -0.0 at an entry 0, as +0 - -0 < -0 - 0 is false: two
// such entries, the constant 0 on the grid's end 0, would tie the other way round).
struct LevelPair { // classify's, read only for its level pairs (no initializers: runs hold 128)
    int lo, hi;
    float smin, smax;
};
enum class BlockKind { Other, Flat, LevelPair };

__attribute__((target("avx2"), always_inline)) inline BlockKind classify(const float src[16], bool snorm, LevelPair& lp) {
    // Flat blocks leave early (they need none of the rest); the other tests are combined
    // without branches.
    const __m256 a = _mm256_loadu_ps(src), b = _mm256_loadu_ps(src + 8);
    const __m256i ai = _mm256_castps_si256(a), bi = _mm256_castps_si256(b);
    const __m256i first = _mm256_broadcastd_epi32(_mm256_castsi256_si128(ai));
    if (_mm256_movemask_epi8(_mm256_and_si256(_mm256_cmpeq_epi32(ai, first), _mm256_cmpeq_epi32(bi, first))) == -1) return BlockKind::Flat;
    __m256 mn = _mm256_min_ps(a, b), mx = _mm256_max_ps(a, b);
    __m128 mn4 = _mm_min_ps(_mm256_castps256_ps128(mn), _mm256_extractf128_ps(mn, 1)), mx4 = _mm_max_ps(_mm256_castps256_ps128(mx), _mm256_extractf128_ps(mx, 1));
    mn4 = _mm_min_ps(mn4, _mm_movehl_ps(mn4, mn4));
    mx4 = _mm_max_ps(mx4, _mm_movehl_ps(mx4, mx4));
    mn4 = _mm_min_ss(mn4, _mm_shuffle_ps(mn4, mn4, 1));
    mx4 = _mm_max_ss(mx4, _mm_shuffle_ps(mx4, mx4, 1));
    lp.smin = _mm_cvtss_f32(mn4);
    lp.smax = _mm_cvtss_f32(mx4);
    // Every texel within +-2 (its magnitude's bits at most 2.0f's: NaN and infinities fail,
    // which MINPS / MAXPS may skip) and none -0.0, on the bits.
    const __m256i magnitude = _mm256_set1_epi32(0x7fffffff), two = _mm256_set1_epi32(0x40000000), negative_zero = _mm256_set1_epi32(int(0x80000000u));
    const __m256i bad = _mm256_or_si256(_mm256_or_si256(_mm256_cmpgt_epi32(_mm256_and_si256(ai, magnitude), two), _mm256_cmpgt_epi32(_mm256_and_si256(bi, magnitude), two)),
                                        _mm256_or_si256(_mm256_cmpeq_epi32(ai, negative_zero), _mm256_cmpeq_epi32(bi, negative_zero)));
    const bool usable = _mm256_testz_si256(bad, bad);
    // The extremes' floor and ceiling, clamped to the levels (as encode computes them; the
    // clamp first keeps the conversion defined), in one register: smin, smax.
    const float scale = snorm ? 127.0f : 255.0f;
    const __m128 lim_lo = _mm_set1_ps(snorm ? -127.0f : 0.0f), lim_hi = _mm_set1_ps(snorm ? 127.0f : 255.0f);
    const __m128 x = _mm_mul_ps(_mm_unpacklo_ps(mn4, mx4), _mm_set1_ps(scale));
    const __m128 fl = _mm_min_ps(_mm_max_ps(_mm_floor_ps(x), lim_lo), lim_hi), cl = _mm_min_ps(_mm_max_ps(_mm_ceil_ps(x), lim_lo), lim_hi);
    const __m128i level = _mm_cvttps_epi32(fl);
    lp.lo = _mm_cvtsi128_si32(level);
    lp.hi = _mm_extract_epi32(level, 1);
    const bool levels = (_mm_movemask_ps(_mm_cmpeq_ps(fl, cl)) & 3) == 3;
    return (usable & levels & (lp.lo < lp.hi)) ? BlockKind::LevelPair : BlockKind::Other;
}

// The byte of a level (SNORM: its two's complement).
int level_byte(int v, bool snorm) { return int(snorm ? uint8_t(int8_t(v)) : uint8_t(v)); }

// N level pairs' first candidates, (hi, lo), each evaluated by its line palette (the same
// keys and results as the candidate loop's evaluation); ok[b] false if one fails (it
// cannot: every key error is finite), which leaves that block to the loop.
struct EightValues {
    detail::Bc4LinePalette pal;
    detail::Bc4LineResult r;
    int k = -1;
};
template <int N>
__attribute__((target("avx2"), always_inline)) inline void eight_values(const PairTables& T, const float* const src[N], const LevelPair* const lp[N],
                                                                       bool snorm, EightValues e[N], bool ok[N]) {
    const detail::Bc4LinePalette* pal[N];
    detail::Bc4LineResult* r[N];
    for (int b = 0; b < N; ++b) {
        e[b].k = level_byte(lp[b]->hi, snorm) * 256 + level_byte(lp[b]->lo, snorm);
        line_palette(T, lp[b]->lo, lp[b]->hi, true, e[b].pal);
        pal[b] = &e[b].pal;
        r[b] = &e[b].r;
    }
    detail::bc4_line_select_avx2<N, true>(pal, src, r, ok);
}

// N level pairs' second candidates, (lo, hi).
template <int N>
__attribute__((target("avx2"), always_inline)) inline void six_values(const PairTables& T, const float* const src[N], const LevelPair* const lp[N],
                                                                     detail::Bc4LineResult r6[N], bool ok[N]) {
    detail::Bc4LinePalette pal6[N];
    const detail::Bc4LinePalette* pal[N];
    detail::Bc4LineResult* r[N];
    for (int b = 0; b < N; ++b) {
        line_palette(T, lp[b]->lo, lp[b]->hi, false, pal6[b]);
        pal[b] = &pal6[b];
        r[b] = &r6[b];
    }
    detail::bc4_line_select_avx2<N>(pal, src, r, ok);
}

// Whether the loop would evaluate the second candidate, (lo, hi), and it could win: not
// after an exact incumbent or endpoints_only's, nor when six_may_tie rules it out.
__attribute__((target("avx2"), always_inline)) inline bool six_needed(const PairTables& T, const LevelPair& lp, const EightValues& e) {
    // Without branches: the keys come late in a block's chain, and a branch on them
    // (mispredicted for about one block in six) costs more than all three tests.
    const int k6 = swapped(e.k);
    const bool exact = (e.r.keys.max_err == 0.0f) & (e.r.keys.sum == 0.0f);
    const bool ends = e.r.endpoints & (lp.smin >= T.end_lo[k6 >> 8]) & (lp.smax <= T.end_hi[k6 & 255]);
    return !exact & !ends & six_may_tie(e.pal, e.r);
}

// The second candidate beats the first: a lower max error, or the same and a lower sum
// (what the loop's evaluation against the incumbent's stop and sum returns, bc4_eval.h).
bool six_beats(bool ok, const detail::Bc4Keys& six, float eight_max, float eight_sum) {
    return ok && (six.max_err < eight_max || (six.max_err == eight_max && six.sum < eight_sum));
}

void write_line_result(int k, const detail::Bc4LineResult& r, uint8_t out[8], BlockResult& res) {
    write_block_bits(uint8_t(k >> 8), uint8_t(k & 255), r.bits, out);
    res = {r.max_err, r.sum_sq, true};
}

} // namespace

namespace detail::bc4 {

// level_pair_blocks (below) for one block, with branches: encode's path (a run of one
// through those passes took 1.3-1.6x this one's time). Returns false for any other block,
// and for a level pair missing the bound (encode_candidates then does it all, to the same
// result).
__attribute__((target("avx2"))) bool level_pair_block(const PairTables& T, const float src[16], bool snorm, bool with_six, float bound, uint8_t out[8],
                                                     BlockResult& res) {
    LevelPair lp;
    const BlockKind kind = classify(src, snorm, lp);
    if (kind == BlockKind::Flat) return T.flat_ready && flat_from_table(T, src[0], snorm, out, res);
    if (kind != BlockKind::LevelPair) return false;
    const float* const in[1] = {src};
    const LevelPair* const pairs[1] = {&lp};
    EightValues e[1];
    detail::Bc4LineResult r6[1];
    bool ok[1], ok6[1];
    eight_values<1>(T, in, pairs, snorm, e, ok);
    if (!ok[0]) return false;
    bool six = with_six && six_needed(T, lp, e[0]);
    if (six) {
        six_values<1>(T, in, pairs, r6, ok6);
        six = six_beats(ok6[0], r6[0].keys, e[0].r.keys.max_err, e[0].r.keys.sum);
    }
    const detail::Bc4LineResult& r = six ? r6[0] : e[0].r;
    if (bound >= 0 && r.max_err > bound) return false;
    write_line_result(six ? swapped(e[0].k) : e[0].k, r, out, res);
    return true;
}

// encode's first steps for fast / normal under the Reference decoder alone, two-sided,
// on AVX2, for a run of blocks: flat blocks from the table, level pairs on their line
// palettes (8-bit sources: nearly every block), everything else and level pairs missing
// the bound by encode_candidates, to the same results (test Bc4.ShortcutsEqualTheSearch).
// In passes over blocks of one kind, so that no branch on a block's kind or on whether
// its 6-value pair is evaluated (both data dependent, and decided late in a block's
// chain) throws away the work on the blocks after it.
__attribute__((target("avx2"))) void level_pair_blocks(const PairTables& T, bool snorm, const BlockOptions& options, const float* src, size_t count,
                                                      uint8_t* out, BlockResult* res) {
    constexpr size_t kRun = 128;
    const bool with_six = options.quality != Quality::Fast;
    const float bound = options.max_error;
    for (size_t r0 = 0; r0 < count; r0 += kRun) {
        const size_t n = std::min(kRun, count - r0);
        const float* s = src + 16 * r0;
        uint8_t* o = out + 8 * r0;
        BlockResult* q = res + r0;
        uint16_t list[3][kRun], six[kRun];
        size_t len[3] = {0, 0, 0}, nsix = 0;
        LevelPair lp[kRun];
        float eight_max[kRun], eight_sum[kRun]; // the first candidate's (the second's comparison)
        int k8[kRun];
        bool more[kRun], redo[kRun]; // per block: no list appends in the passes' chains
        uint8_t kind[kRun];
        for (size_t i = 0; i < n; ++i) {
            kind[i] = uint8_t(classify(s + 16 * i, snorm, lp[i]));
            more[i] = redo[i] = false;
        }
        for (size_t i = 0; i < n; ++i) list[kind[i]][len[kind[i]]++] = uint16_t(i);
        for (size_t j = 0; j < len[int(BlockKind::Flat)]; ++j) {
            const size_t i = list[int(BlockKind::Flat)][j];
            redo[i] = !(T.flat_ready && flat_from_table(T, s[16 * i], snorm, o + 8 * i, q[i]));
        }
        // Level pairs two at a time (bc4_line_select_avx2's interleaving): a group's blocks
        // from position j of a list of `listed` (the last of an odd list alone).
        constexpr int kPair = 2;
        struct Group {
            int m;
            size_t at[kPair];
            const float* in[kPair];
            const LevelPair* pairs[kPair];
        };
        auto group = [&](const uint16_t* ids, size_t j, size_t listed) {
            Group g;
            g.m = int(std::min<size_t>(kPair, listed - j));
            for (int b = 0; b < g.m; ++b) {
                g.at[b] = ids[j + size_t(b)];
                g.in[b] = s + 16 * g.at[b];
                g.pairs[b] = &lp[g.at[b]];
            }
            return g;
        };
        const size_t npairs = len[int(BlockKind::LevelPair)];
        for (size_t j = 0; j < npairs; j += kPair) {
            const Group g = group(list[int(BlockKind::LevelPair)], j, npairs);
            EightValues e[kPair];
            bool ok[kPair];
            if (g.m == kPair) eight_values<kPair>(T, g.in, g.pairs, snorm, e, ok);
            else eight_values<1>(T, g.in, g.pairs, snorm, e, ok); // a single block (encode) or an odd run's last
            for (int b = 0; b < g.m; ++b) {
                const size_t i = g.at[b];
                write_line_result(e[b].k, e[b].r, o + 8 * i, q[i]);
                more[i] = ok[b] & with_six & six_needed(T, lp[i], e[b]);
                eight_max[i] = e[b].r.keys.max_err;
                eight_sum[i] = e[b].r.keys.sum;
                k8[i] = e[b].k;
                redo[i] = (!ok[b]) | ((!more[i]) & (bound >= 0) & (e[b].r.max_err > bound));
            }
        }
        for (size_t i = 0; i < n; ++i) {
            six[nsix] = uint16_t(i);
            nsix += more[i] ? 1 : 0;
        }
        // The second candidates, two at a time too.
        for (size_t j = 0; j < nsix; j += kPair) {
            const Group g = group(six, j, nsix);
            detail::Bc4LineResult r6[kPair];
            bool ok[kPair];
            if (g.m == kPair) six_values<kPair>(T, g.in, g.pairs, r6, ok);
            else six_values<1>(T, g.in, g.pairs, r6, ok);
            for (int b = 0; b < g.m; ++b) {
                const size_t i = g.at[b];
                if (six_beats(ok[b], r6[b].keys, eight_max[i], eight_sum[i])) write_line_result(swapped(k8[i]), r6[b], o + 8 * i, q[i]);
                redo[i] = bound >= 0 && q[i].max_error > bound;
            }
        }
        auto& other = list[int(BlockKind::Other)];
        size_t& nother = len[int(BlockKind::Other)];
        for (size_t i = 0; i < n; ++i)
            if (redo[i]) other[nother++] = uint16_t(i);
        for (size_t j = 0; j < nother; ++j) {
            const size_t i = other[j];
            q[i] = encode_candidates(T, snorm, options, s + 16 * i, o + 8 * i);
        }
    }
}

} // namespace detail::bc4
#endif

namespace detail {
// Test hook (bc4_test_hooks.h): the line palettes' evaluations of the level pair (lo, hi), both
// modes, against the full evaluation of the same pairs' palettes in index order.
#if defined(ATLAS_BC4_AVX2)
namespace {
__attribute__((target("avx2"))) long line_mismatches_avx2(const PairTables* T, bool snorm, const float* blocks, size_t count, int lo, int hi) {
    long bad = 0;
    const LevelPair pair{lo, hi, 0.0f, 0.0f};
    const LevelPair* const pairs[1] = {&pair};
    for (size_t b = 0; b < count; ++b) {
        const float* const in[1] = {blocks + 16 * b};
        EightValues e[1];
        detail::Bc4LineResult six[1];
        bool ok[2];
        eight_values<1>(*T, in, pairs, snorm, e, ok);
        six_values<1>(*T, in, pairs, six, ok + 1);
        const detail::Bc4LineResult* r[2] = {&e[0].r, &six[0]};
        detail::Bc4Keys full[2];
        for (int m = 0; m < 2; ++m) {
            const detail::Palette<1>& p = T->pal[size_t(m == 0 ? e[0].k : swapped(e[0].k))];
            const bool fok = detail::bc4_keys_portable<false>(p, in[0], detail::kBc4Infeasible, INFINITY, full[m]);
            float mx;
            double sq;
            uint64_t bits;
            detail::bc4_exact_portable<false>(p, in[0], full[m], mx, sq, bits);
            bad += ok[m] != fok || std::memcmp(r[m]->keys.key, full[m].key, sizeof full[m].key) != 0 ||
                   std::memcmp(&r[m]->keys.max_err, &full[m].max_err, 4) != 0 || std::memcmp(&r[m]->keys.sum, &full[m].sum, 4) != 0 ||
                   std::memcmp(&r[m]->max_err, &mx, 4) != 0 || std::memcmp(&r[m]->sum_sq, &sq, 8) != 0 || r[m]->bits != bits ||
                   r[m]->endpoints != endpoints_only(full[m]);
            // six_may_tie's skip: the 6-value pair's evaluation against the 8-value incumbent returns false.
            if (m == 1 && !six_may_tie(e[0].pal, e[0].r)) {
                detail::Bc4Keys tied;
                bad += detail::bc4_keys_portable<false>(p, in[0], full[0].max_err, full[0].sum, tied) ? 1 : 0;
            }
        }
    }
    return bad;
}
} // namespace
#endif

long bc4_line_mismatches(bool snorm, const float* blocks, size_t count, int lo, int hi) {
#if defined(ATLAS_BC4_AVX2)
    if (!bc4_cpu_has_avx2()) return 0;
    auto T = std::make_unique<PairTables>();
    build_tables(*T, snorm, kReferenceOnly);
    return line_mismatches_avx2(T.get(), snorm, blocks, count, lo, hi);
#else
    (void)snorm, (void)blocks, (void)count, (void)lo, (void)hi;
    return 0;
#endif
}
} // namespace detail

} // namespace atlas::compress

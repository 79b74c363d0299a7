// Internal: BC4 `fast` / `normal` candidate evaluation in one pass over the palette.
//
// Each texel takes the entry of least worst-case error over the decoder set, found as the
// minimum of a key: the error's float bits with the 3 low bits replaced by the entry index
// (errors are >= 0, so their bits order like the floats; the 3 bits break ties by index
// and cost at most 7 ulps of precision in the comparison). A candidate is ranked by the
// largest key error, then by the float sum of the squared key errors; the winner's exact
// errors are recomputed from its indices (bc4_search.cpp). One pass replaces select_indices'
// two (minimum, then the squared-error choice), which is what `best` keeps.
//
// The SSE2 path and the portable path perform the same IEEE operations in the same order
// (MAXPS(a, b) is `a > b ? a : b`, MINPS likewise; the sum of squares per lane over the 4
// groups of 4 texels, then (lane 0 + lane 1) + (lane 2 + lane 3)), so they return the same
// keys and sums (test Bc4Eval.Sse2EqualsPortable).
#pragma once

#include "simd_choice.h"
#include "atlas/compress/decoder_model.h"
#include "palette_search.h"

#include <bit>
#include <cstdint>
#include <cstring>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif
#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>
#define ATLAS_BC4_AVX2 1 // functions compiled for AVX2 by attribute, run after a CPU check
#endif

namespace atlas::compress::detail {

// Left uninitialised (the evaluations write every field they return true for): zeroing
// two of them per block cost a tenth of the encode.
struct Bc4Keys {
    float max_err; // largest key error (the error with its 3 low bits cleared)
    float sum;     // sum of squared key errors (float, fixed order)
    uint32_t key[16];
};

// The error of an infeasible entry (one-sided: above the source), 2^127; larger errors
// (and NaN) are clamped to it. Its 3 low bits are 0, so a key error equal to it marks
// the texel infeasible.
inline constexpr float kBc4Infeasible = 1.7014118346046923e38f;
inline constexpr uint32_t kBc4KeyMask = ~uint32_t(7);
static_assert(std::bit_cast<uint32_t>(kBc4Infeasible) == 0x7f000000u);

inline float bc4_key_error(uint32_t key) {
    const uint32_t b = key & kBc4KeyMask;
    float f;
    std::memcpy(&f, &b, 4);
    return f;
}

inline bool bc4_keys_better(const Bc4Keys& a, const Bc4Keys& b) {
    return a.max_err < b.max_err || (a.max_err == b.max_err && a.sum < b.sum);
}

// inc_sum: the incumbent's sum (with stop its max error; +inf and kBc4Infeasible: none).
// Returns false too when the max error equals stop and the sum is not below inc_sum (the
// candidate cannot win: ranking is by max error, then sum); the partial sums of squares
// only grow, so each path drops such a candidate as soon as a texel ties and its partial
// sum reaches inc_sum, and all paths return the same.
// src: 16 finite texels within +-1e30. Returns false when some texel has no feasible entry or a key error exceeds `stop`.
// One texel's key: the palette entry with the least error (the error's float bits
// above the entry's index, so comparing keys as floats breaks ties by the lowest index).
template <bool OneSided>
inline uint32_t bc4_texel_key(const Palette<1>& p, float s) {
    uint32_t best = 0;
    float best_f = 0;
    for (int i = 0; i < p.n; ++i) {
        const float a = p.hi[i][0] - s, b = s - p.lo[i][0];
        float e = a > b ? a : b;
        if constexpr (OneSided)
            if (p.hi[i][0] > s) e = kBc4Infeasible;
        uint32_t bits;
        std::memcpy(&bits, &e, 4);
        const uint32_t key = (bits & kBc4KeyMask) | uint32_t(i);
        float kf;
        std::memcpy(&kf, &key, 4);
        if (i == 0 || kf < best_f) { best = key; best_f = kf; }
    }
    return best;
}

template <bool OneSided>
inline bool bc4_keys_portable(const Palette<1>& p, const float* src, float stop, float inc_sum, Bc4Keys& out) {
    float acc[4] = {0, 0, 0, 0}, mx = 0;
    for (int q = 0; q < 4; ++q) {
        float qmax = 0;
        for (int j = 0; j < 4; ++j) {
            const int t = 4 * q + j;
            const uint32_t best = bc4_texel_key<OneSided>(p, src[t]);
            out.key[t] = best;
            const float ek = bc4_key_error(best);
            qmax = ek > qmax ? ek : qmax;
            acc[j] = acc[j] + ek * ek;
        }
        if (qmax > stop || !(qmax < kBc4Infeasible)) return false;
        mx = qmax > mx ? qmax : mx;
        if (mx == stop && !(((acc[0] + acc[1]) + (acc[2] + acc[3])) < inc_sum)) return false; // tied, not below
    }
    out.max_err = mx;
    out.sum = (acc[0] + acc[1]) + (acc[2] + acc[3]);
    return true;
}

#if defined(__SSE2__)
template <bool OneSided>
inline bool bc4_keys_sse2(const Palette<1>& p, const float* src, float stop, float inc_sum, Bc4Keys& out) {
    const __m128 zero = _mm_setzero_ps(), vstop = _mm_set1_ps(stop), vinf = _mm_set1_ps(kBc4Infeasible);
    const __m128 clear = _mm_castsi128_ps(_mm_set1_epi32(int(kBc4KeyMask)));
    __m128 acc = zero, mx = zero;
    for (int q = 0; q < 4; ++q) {
        const __m128 s = _mm_loadu_ps(src + 4 * q);
        __m128 best = zero;
        for (int i = 0; i < p.n; ++i) {
            const __m128 vlo = _mm_set1_ps(p.lo[i][0]), vhi = _mm_set1_ps(p.hi[i][0]);
            __m128 e = _mm_max_ps(_mm_sub_ps(vhi, s), _mm_sub_ps(s, vlo));
            if constexpr (OneSided) {
                const __m128 above = _mm_cmpgt_ps(vhi, s);
                e = _mm_or_ps(_mm_and_ps(above, vinf), _mm_andnot_ps(above, e));
            }
            const __m128 key = _mm_or_ps(_mm_and_ps(e, clear), _mm_castsi128_ps(_mm_set1_epi32(i)));
            best = i == 0 ? key : _mm_min_ps(key, best);
        }
        _mm_storeu_ps(reinterpret_cast<float*>(out.key + 4 * q), best);
        const __m128 ek = _mm_and_ps(best, clear);
        // Per-lane running max of the groups so far, as the portable code's max over texels.
        if (_mm_movemask_ps(_mm_or_ps(_mm_cmpgt_ps(ek, vstop), _mm_cmpge_ps(ek, vinf)))) return false;
        mx = _mm_max_ps(ek, mx);
        acc = _mm_add_ps(acc, _mm_mul_ps(ek, ek));
        if (_mm_movemask_ps(_mm_cmpeq_ps(mx, vstop))) { // a texel ties the incumbent's max: the sum decides
            float a[4];
            _mm_storeu_ps(a, acc);
            if (!(((a[0] + a[1]) + (a[2] + a[3])) < inc_sum)) return false;
        }
    }
    float a[4], m[4];
    _mm_storeu_ps(a, acc);
    _mm_storeu_ps(m, mx);
    float r = m[0];
    for (int j = 1; j < 4; ++j) r = m[j] > r ? m[j] : r;
    out.max_err = r;
    out.sum = (a[0] + a[1]) + (a[2] + a[3]);
    return true;
}
#endif

// A flat block (16 equal texels): one texel's evaluation, with the sums formed as above,
// so the same keys, maxima and sums as the 16-texel paths.
template <bool OneSided>
inline bool bc4_keys_flat(const Palette<1>& p, const float* src, float stop, float inc_sum, Bc4Keys& out) {
    const uint32_t best = bc4_texel_key<OneSided>(p, src[0]);
    const float ek = bc4_key_error(best);
    if (ek > stop || !(ek < kBc4Infeasible)) return false;
    {
        const float sq = ek * ek, lane = ((sq + sq) + sq) + sq;
        if (ek == stop && !(((lane + lane) + (lane + lane)) < inc_sum)) return false;
    }
    for (int t = 0; t < 16; ++t) out.key[t] = best;
    const float sq = ek * ek, lane = ((sq + sq) + sq) + sq;
    out.max_err = ek > 0.0f ? ek : 0.0f;
    out.sum = (lane + lane) + (lane + lane);
    return true;
}

// The exact result of the chosen indices: each texel's entry_error_t (only texels whose
// key error equals the block's largest can hold the block's maximum: a texel's exact
// error has the bits of its key error plus 0..7) and the squared Reference error in
// double, in 4 partial sums (texel t into t % 4), then (0 + 1) + (2 + 3); `bits`: the
// 16 3-bit indices, texel 0 lowest (the block's index field).
template <bool OneSided>
inline void bc4_exact_portable(const Palette<1>& p, const float* src, const Bc4Keys& k, float& max_err, double& sum_sq, uint64_t& bits) {
    float mx = 0;
    double sq[4] = {0, 0, 0, 0};
    bits = 0;
    for (int t = 0; t < 16; ++t) {
        const int i = int(k.key[t] & 7u);
        bits |= uint64_t(i) << (3 * t);
        if (bc4_key_error(k.key[t]) == k.max_err) {
            const float e = entry_error_t<1, OneSided>(p, i, src + t);
            mx = e > mx ? e : mx;
        }
        const double d = double(p.ref[i][0]) - src[t];
        sq[t & 3] += d * d;
    }
    max_err = mx;
    sum_sq = (sq[0] + sq[1]) + (sq[2] + sq[3]);
}

// bc4_exact_portable for a flat block (16 texels with the same bits, all with the same key):
// one texel's error, and the squared error summed as there (4 per partial sum).
template <bool OneSided>
inline void bc4_exact_flat(const Palette<1>& p, const float* src, const Bc4Keys& k, float& max_err, double& sum_sq, uint64_t& bits) {
    const int i = int(k.key[0] & 7u);
    const float e = entry_error_t<1, OneSided>(p, i, src);
    max_err = e > 0.0f ? e : 0.0f;
    const double d = double(p.ref[i][0]) - src[0], q = d * d;
    const double lane = ((q + q) + q) + q;
    sum_sq = (lane + lane) + (lane + lane);
    bits = uint64_t(i) * 0x249249249249ull; // i in each of the 16 3-bit fields
}

#if defined(ATLAS_BC4_AVX2)
// AVX2: 8 texels at a time, the same operations per texel; the sums are formed in the
// portable order (lanes of texels j, 4 + j, 8 + j, 12 + j, then (0 + 1) + (2 + 3)).
template <bool OneSided>
__attribute__((target("avx2"))) inline bool bc4_keys_avx2(const Palette<1>& p, const float* src, float stop, float inc_sum, Bc4Keys& out) {
    const __m256 vstop = _mm256_set1_ps(stop), vinf = _mm256_set1_ps(kBc4Infeasible);
    const __m256 clear = _mm256_castsi256_ps(_mm256_set1_epi32(int(kBc4KeyMask)));
    __m256 ek[2];
    for (int h = 0; h < 2; ++h) {
        const __m256 s = _mm256_loadu_ps(src + 8 * h);
        // The 8 entries' keys (p.n is always 8), then their minimum as a tree: the keys
        // differ in their index bits and are not NaN, so any order gives the same minimum,
        // and the tree's 3 dependent minima replace a chain of 7 (latency-bound).
        static_assert(sizeof(p.lo) / sizeof(p.lo[0]) == 8, "BC4 palettes have 8 entries");
        __m256 key[8];
        for (int i = 0; i < 8; ++i) {
            const __m256 vlo = _mm256_set1_ps(p.lo[i][0]), vhi = _mm256_set1_ps(p.hi[i][0]);
            __m256 e = _mm256_max_ps(_mm256_sub_ps(vhi, s), _mm256_sub_ps(s, vlo));
            if constexpr (OneSided) {
                const __m256 above = _mm256_cmp_ps(vhi, s, _CMP_GT_OQ);
                e = _mm256_blendv_ps(e, vinf, above);
            }
            key[i] = _mm256_or_ps(_mm256_and_ps(e, clear), _mm256_castsi256_ps(_mm256_set1_epi32(i)));
        }
        const __m256 best = _mm256_min_ps(_mm256_min_ps(_mm256_min_ps(key[0], key[1]), _mm256_min_ps(key[2], key[3])),
                                          _mm256_min_ps(_mm256_min_ps(key[4], key[5]), _mm256_min_ps(key[6], key[7])));
        _mm256_storeu_ps(reinterpret_cast<float*>(out.key + 8 * h), best);
        ek[h] = _mm256_and_ps(best, clear);
        if (_mm256_movemask_ps(_mm256_or_ps(_mm256_cmp_ps(ek[h], vstop, _CMP_GT_OQ), _mm256_cmp_ps(ek[h], vinf, _CMP_GE_OQ)))) return false;
        if (h == 0 && _mm256_movemask_ps(_mm256_cmp_ps(ek[0], vstop, _CMP_EQ_OQ))) {
            // A texel ties the incumbent's max: the sum decides; the first two groups' lane sums
            // can only grow, so the candidate is dropped once they reach the incumbent's.
            const __m256 sq = _mm256_mul_ps(ek[0], ek[0]);
            float a[4];
            _mm_storeu_ps(a, _mm_add_ps(_mm256_castps256_ps128(sq), _mm256_extractf128_ps(sq, 1)));
            if (!(((a[0] + a[1]) + (a[2] + a[3])) < inc_sum)) return false;
        }
    }
    const __m256 sq0 = _mm256_mul_ps(ek[0], ek[0]), sq1 = _mm256_mul_ps(ek[1], ek[1]);
    const __m128 acc = _mm_add_ps(_mm_add_ps(_mm_add_ps(_mm256_castps256_ps128(sq0), _mm256_extractf128_ps(sq0, 1)), _mm256_castps256_ps128(sq1)),
                                  _mm256_extractf128_ps(sq1, 1));
    // The largest of the 16 (errors are >= 0 and not NaN: any order gives the same) and
    // the sum as (0 + 1) + (2 + 3), both in registers.
    const __m256 m8 = _mm256_max_ps(ek[1], ek[0]);
    const float r = max_of_lanes(_mm_max_ps(_mm256_castps256_ps128(m8), _mm256_extractf128_ps(m8, 1)));
    const __m128 pairs = _mm_hadd_ps(acc, acc); // (0 + 1), (2 + 3)
    out.max_err = r;
    out.sum = _mm_cvtss_f32(_mm_hadd_ps(pairs, pairs));
    return !(r == stop && !(out.sum < inc_sum));
}

// A pair's palette in ascending order of value, for the Reference decoder alone (each
// entry's interval is its exact value to ulps) and two-sided errors: the 8-value mode's
// 8 evenly spaced values, or the 6-value mode's constant below, its 6 evenly spaced
// values and the constant above. Position u = s * per_value + offset of a value s on the
// even grid (the lowest grid value at position 0, or 1 after a constant) tells the two
// entries around s; no other entry can hold the least key when the grid's spacing (>= 1/7
// level, ~5.6e-4 UNORM) is far above the keys' resolution (8 ulps of the error; texels
// within +-2 keep errors below 3, ulps below 2.4e-7), so the two give the same least key
// as all 8 (test
// Bc4Eval.LineKeysEqualFullKeys). Entries with the same value (a constant on a grid end)
// tie on the error and the grid end, with the lower index, wins in both evaluations
// (texels -0.0 excepted: bc4_avx2.cpp keeps them off this path).
struct Bc4LinePalette {
    __m256 lo, hi, ref;    // ascending (used only in AVX2 functions)
    const int32_t* index;  // BC4 index of each position
    float origin, per_value; // the lowest grid value, grid steps per unit value
    float offset;            // position of value 0: the lowest grid value's (0, or 1 after a constant) - origin * per_value
};

// A line palette's evaluation: its keys, largest key error and sum as bc4_keys_avx2
// computes them for the same palette in index order (stop and inc_sum at their "none"
// values), and bc4_exact_avx2's results for the chosen indices, in one pass.
struct Bc4LineResult {
    Bc4Keys keys;
    float max_err;   // exact (bc4_exact_avx2)
    double sum_sq;   // exact
    uint64_t bits;   // the index field
    bool endpoints;  // every texel took index 0 or 1 (endpoints_only)
    float six_far;   // 8-value palettes, with SixGrid: the largest distance to the 6-value grid, in its steps
};

// N blocks at once (each with its palette), their operations interleaved: a block's
// evaluation is one chain of dependent steps, and N independent chains keep the core
// busy where one leaves it waiting. Returns, per block, false if a texel has no
// feasible entry (not for the Reference decoder's two-sided errors, the only use).
// Each sum is formed in its evaluation's order.
// SixGrid (8-value palettes): also each texel's distance to the 6-value grid of the same
// ends, from the same position (5 steps for 7), for six_may_tie in bc4_avx2.cpp.
template <int N, bool SixGrid = false>
__attribute__((target("avx2"))) inline void bc4_line_select_avx2(const Bc4LinePalette* const p[N], const float* const src[N], Bc4LineResult* const out[N],
                                                               bool ok[N]) {
    const __m256 clear = _mm256_castsi256_ps(_mm256_set1_epi32(int(kBc4KeyMask))), zero = _mm256_setzero_ps();
    const __m256i seven = _mm256_set1_epi32(7), shifts = _mm256_setr_epi32(0, 3, 6, 9, 12, 15, 18, 21);
    __m256 ek[N][2], mx[N];
    __m256d acc[N];
    __m256i taken[N];
    __m256 far[N];
    uint32_t half[N][2];
    for (int b = 0; b < N; ++b) {
        far[b] = zero;
        mx[b] = zero;
        acc[b] = _mm256_setzero_pd();
        taken[b] = _mm256_setzero_si256();
    }
    for (int h = 0; h < 2; ++h)
        for (int b = 0; b < N; ++b) {
            const Bc4LinePalette& q = *p[b];
            const __m256i index = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(q.index));
            const __m256 s = _mm256_loadu_ps(src[b] + 8 * h);
            // The lower entry's position, clamped to 0..6 (a truncation of u in (-1, 0) is 0:
            // the clamp's value too; texels beyond the ends take the two end entries). u is
            // within ~1e-3 of the exact position (|s * per_value| < 4e3): any error below
            // half a step brackets the nearest entry, which is all the keys need.
            const __m256 u = _mm256_add_ps(_mm256_mul_ps(s, _mm256_set1_ps(q.per_value)), _mm256_set1_ps(q.offset));
            const __m256i at = _mm256_min_epi32(_mm256_max_epi32(_mm256_cvttps_epi32(u), _mm256_setzero_si256()), _mm256_set1_epi32(6));
            const __m256i above = _mm256_add_epi32(at, _mm256_set1_epi32(1));
            if constexpr (SixGrid) {
                // Nearest grid step, unclamped: beyond the grid's ends this finds a step that
                // does not exist, nearer than the true end, so the test only errs toward
                // evaluating the 6-value pair.
                const __m256 u6 = _mm256_mul_ps(u, _mm256_set1_ps(5.0f / 7.0f));
                const __m256 n6 = _mm256_round_ps(u6, _MM_FROUND_TO_NEAREST_INT | _MM_FROUND_NO_EXC);
                far[b] = _mm256_max_ps(far[b], _mm256_andnot_ps(_mm256_set1_ps(-0.0f), _mm256_sub_ps(u6, n6)));
            }
            const __m256 e0 = _mm256_max_ps(_mm256_sub_ps(_mm256_permutevar8x32_ps(q.hi, at), s), _mm256_sub_ps(s, _mm256_permutevar8x32_ps(q.lo, at)));
            const __m256 e1 = _mm256_max_ps(_mm256_sub_ps(_mm256_permutevar8x32_ps(q.hi, above), s), _mm256_sub_ps(s, _mm256_permutevar8x32_ps(q.lo, above)));
            const __m256 k0 = _mm256_or_ps(_mm256_and_ps(e0, clear), _mm256_castsi256_ps(_mm256_permutevar8x32_epi32(index, at)));
            const __m256 k1 = _mm256_or_ps(_mm256_and_ps(e1, clear), _mm256_castsi256_ps(_mm256_permutevar8x32_epi32(index, above)));
            const __m256 best = _mm256_min_ps(k0, k1);           // k0 < k1 ? k0 : k1
            const __m256 take1 = _mm256_cmp_ps(k0, k1, _CMP_NLT_UQ); // where the min took k1
            _mm256_storeu_ps(reinterpret_cast<float*>(out[b]->keys.key + 8 * h), best);
            ek[b][h] = _mm256_and_ps(best, clear);
            // bc4_exact_avx2's terms for the chosen entry: its error (the same expression) and
            // its Reference value's squared difference in double.
            mx[b] = _mm256_max_ps(_mm256_max_ps(_mm256_blendv_ps(e0, e1, take1), zero), mx[b]);
            const __m256 r = _mm256_blendv_ps(_mm256_permutevar8x32_ps(q.ref, at), _mm256_permutevar8x32_ps(q.ref, above), take1);
            const __m256d d0 = _mm256_sub_pd(_mm256_cvtps_pd(_mm256_castps256_ps128(r)), _mm256_cvtps_pd(_mm256_castps256_ps128(s)));
            const __m256d d1 = _mm256_sub_pd(_mm256_cvtps_pd(_mm256_extractf128_ps(r, 1)), _mm256_cvtps_pd(_mm256_extractf128_ps(s, 1)));
            acc[b] = _mm256_add_pd(acc[b], _mm256_mul_pd(d0, d0));
            acc[b] = _mm256_add_pd(acc[b], _mm256_mul_pd(d1, d1));
            const __m256i sel = _mm256_and_si256(_mm256_castps_si256(best), seven);
            taken[b] = _mm256_or_si256(taken[b], sel);
            __m256i x = _mm256_sllv_epi32(sel, shifts);
            x = _mm256_or_si256(x, _mm256_shuffle_epi32(x, 0x4E));
            x = _mm256_or_si256(x, _mm256_shuffle_epi32(x, 0xB1));
            half[b][h] = uint32_t(_mm_cvtsi128_si32(_mm_or_si128(_mm256_castsi256_si128(x), _mm256_extracti128_si256(x, 1))));
        }
    for (int b = 0; b < N; ++b) {
        Bc4LineResult& o = *out[b];
        // The keys' largest error and sum, as bc4_rank_avx2 forms them.
        const __m256 sq0 = _mm256_mul_ps(ek[b][0], ek[b][0]), sq1 = _mm256_mul_ps(ek[b][1], ek[b][1]);
        const __m128 ksum = _mm_add_ps(_mm_add_ps(_mm_add_ps(_mm256_castps256_ps128(sq0), _mm256_extractf128_ps(sq0, 1)), _mm256_castps256_ps128(sq1)),
                                       _mm256_extractf128_ps(sq1, 1));
        const __m256 m8 = _mm256_max_ps(ek[b][1], ek[b][0]);
        o.keys.max_err = max_of_lanes(_mm_max_ps(_mm256_castps256_ps128(m8), _mm256_extractf128_ps(m8, 1)));
        const __m128 kpairs = _mm_hadd_ps(ksum, ksum);
        o.keys.sum = _mm_cvtss_f32(_mm_hadd_ps(kpairs, kpairs));
        o.max_err = max_of_lanes(_mm_max_ps(_mm256_castps256_ps128(mx[b]), _mm256_extractf128_ps(mx[b], 1)));
        const __m128d pairs = _mm_hadd_pd(_mm256_castpd256_pd128(acc[b]), _mm256_extractf128_pd(acc[b], 1)); // (0 + 1), (2 + 3)
        o.sum_sq = _mm_cvtsd_f64(_mm_hadd_pd(pairs, pairs));
        o.bits = uint64_t(half[b][0]) | (uint64_t(half[b][1]) << 24);
        o.endpoints = _mm256_testz_si256(taken[b], _mm256_set1_epi32(6));
        o.six_far = SixGrid ? max_of_lanes(_mm_max_ps(_mm256_castps256_ps128(far[b]), _mm256_extractf128_ps(far[b], 1))) : 0.0f;
        ok[b] = o.keys.max_err < kBc4Infeasible;
    }
}


// The exact errors of the chosen entries (entry_error_t's terms; every chosen entry is
// feasible) and the squared Reference error in double, summed in exact_selection's
// order (lanes of texels j, 4 + j, 8 + j, 12 + j, then (0 + 1) + (2 + 3)); the block's
// max error is the max over all texels, which equals the max over the texels whose key
// error is the largest (bc4_search.cpp).
__attribute__((target("avx2"))) inline void bc4_exact_avx2(const Palette<1>& p, const float* src, const Bc4Keys& k, float& max_err,
                                                           double& sum_sq, uint64_t& bits) {
    static_assert(sizeof(p.lo) == 8 * sizeof(float), "one channel: 8 contiguous entries");
    const __m256 lo = _mm256_loadu_ps(&p.lo[0][0]), hi = _mm256_loadu_ps(&p.hi[0][0]), ref = _mm256_loadu_ps(&p.ref[0][0]);
    const __m256 zero = _mm256_setzero_ps();
    __m256 mx = zero;
    __m256d acc = _mm256_setzero_pd();
    uint32_t half[2];
    const __m256i shifts = _mm256_setr_epi32(0, 3, 6, 9, 12, 15, 18, 21);
    for (int h = 0; h < 2; ++h) {
        const __m256i sel = _mm256_and_si256(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(k.key + 8 * h)), _mm256_set1_epi32(7));
        // The 8 indices at 3-bit offsets, OR-reduced to 24 bits.
        __m256i b = _mm256_sllv_epi32(sel, shifts);
        b = _mm256_or_si256(b, _mm256_shuffle_epi32(b, 0x4E));
        b = _mm256_or_si256(b, _mm256_shuffle_epi32(b, 0xB1));
        half[h] = uint32_t(_mm_cvtsi128_si32(_mm_or_si128(_mm256_castsi256_si128(b), _mm256_extracti128_si256(b, 1))));
        const __m256 s = _mm256_loadu_ps(src + 8 * h);
        const __m256 l = _mm256_permutevar8x32_ps(lo, sel), u = _mm256_permutevar8x32_ps(hi, sel), r = _mm256_permutevar8x32_ps(ref, sel);
        const __m256 e = _mm256_max_ps(_mm256_max_ps(_mm256_sub_ps(u, s), _mm256_sub_ps(s, l)), zero);
        mx = _mm256_max_ps(e, mx);
        const __m256d d0 = _mm256_sub_pd(_mm256_cvtps_pd(_mm256_castps256_ps128(r)), _mm256_cvtps_pd(_mm256_castps256_ps128(s)));
        const __m256d d1 = _mm256_sub_pd(_mm256_cvtps_pd(_mm256_extractf128_ps(r, 1)), _mm256_cvtps_pd(_mm256_extractf128_ps(s, 1)));
        acc = _mm256_add_pd(acc, _mm256_mul_pd(d0, d0));
        acc = _mm256_add_pd(acc, _mm256_mul_pd(d1, d1));
    }
    max_err = max_of_lanes(_mm_max_ps(_mm256_castps256_ps128(mx), _mm256_extractf128_ps(mx, 1)));
    const __m128d pairs = _mm_hadd_pd(_mm256_castpd256_pd128(acc), _mm256_extractf128_pd(acc, 1)); // (0 + 1), (2 + 3)
    sum_sq = _mm_cvtsd_f64(_mm_hadd_pd(pairs, pairs));
    bits = uint64_t(half[0]) | (uint64_t(half[1]) << 24);
}

inline bool bc4_cpu_has_avx2() { return !simd_env_forbids_avx2() && __builtin_cpu_supports("avx2") != 0; }
#else
inline bool bc4_cpu_has_avx2() { return false; }
#endif

template <bool OneSided>
inline bool bc4_keys(const Palette<1>& p, const float* src, float stop, float inc_sum, Bc4Keys& out) {
#if defined(__SSE2__)
    return bc4_keys_sse2<OneSided>(p, src, stop, inc_sum, out);
#else
    return bc4_keys_portable<OneSided>(p, src, stop, inc_sum, out);
#endif
}

} // namespace atlas::compress::detail

// Internal: choosing the 16 indices of a block for a palette of intervals.
//
// A decoder set turns each palette entry into an interval [lo, hi] per channel that
// contains the entry's decoded value under every decoder of the set, and is tight
// (lo and hi are reached). So max over decoders |dec - s| = max(hi - s, s - lo) and
// "every decoder <= s" is exactly hi <= s: the guarantees reduce to interval tests.
#pragma once

#include <algorithm>
#include <cstdint>
#include <limits>
#include <type_traits>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace atlas::compress::detail {

template <int C>
struct Palette {
    int n = 0;
    float lo[8][C];
    float hi[8][C];
    float ref[8][C]; // Reference decoder value (for the squared-error tie break)
};

struct Selection {
    float max_err = std::numeric_limits<float>::infinity();
    double sum_sq = 0;
    uint8_t idx[16] = {};
};

// Lexicographic objective: max error first, then squared reference error.
inline bool better(const Selection& a, const Selection& b) {
    return a.max_err < b.max_err || (a.max_err == b.max_err && a.sum_sq < b.sum_sq);
}

// The objective within a max-error budget (BC1 RGB given a bound; budget < 0: none, then
// this is `better`): a selection within the budget beats one over it; among those within
// it the smaller squared error wins (then the smaller max error); among those over it,
// `better` decides. A strict weak order, so a search keeps improving one incumbent.
inline bool better_within(const Selection& a, const Selection& b, float budget) {
    const bool fa = a.max_err <= budget, fb = b.max_err <= budget;
    if (fa != fb) return fa;
    if (fa) return a.sum_sq < b.sum_sq || (a.sum_sq == b.sum_sq && a.max_err < b.max_err);
    return better(a, b);
}

// Per-texel worst-case error of entry i; +inf when one-sided and above the source.
template <int C, bool OneSided>
inline float entry_error_t(const Palette<C>& p, int i, const float* s) {
    float e = 0;
    for (int c = 0; c < C; ++c) {
        if constexpr (OneSided)
            if (p.hi[i][c] > s[c]) return std::numeric_limits<float>::infinity();
        const float a = p.hi[i][c] - s[c], b = s[c] - p.lo[i][c];
        e = std::max(e, a > b ? a : b);
    }
    return e;
}

#if defined(__SSE2__)
// The largest of 4 errors (>= 0, never NaN, so the order of the maxima does not matter).
inline float max_of_lanes(__m128 v) {
    v = _mm_max_ps(v, _mm_movehl_ps(v, v));
    return _mm_cvtss_f32(_mm_max_ss(v, _mm_shuffle_ps(v, v, 1)));
}

// C == 1 (BC4, bc1-scalar), the encoders' hot loop, with SSE2 (x86-64 baseline):
// the same IEEE operations as the generic path, hence the same choices. MAXPS(a, b)
// is exactly `a > b ? a : b` and MINPS(a, b) `a < b ? a : b`, as written there.
template <bool OneSided>
inline Selection select_indices_scalar_t(const Palette<1>& p, const float* src, float stop_above) {
    const __m128 zero = _mm_setzero_ps(), vinf = _mm_set1_ps(std::numeric_limits<float>::infinity());
    Selection out;
    __m128 s[4], err[8][4], block = zero;
    const __m128 vstop = _mm_set1_ps(stop_above);
    // Quads of texels in order, each against every entry, so that a candidate that
    // cannot beat the incumbent is usually dropped after the first quad.
    for (int q = 0; q < 4; ++q) {
        s[q] = _mm_loadu_ps(src + 4 * q);
        __m128 best = vinf;
        for (int i = 0; i < p.n; ++i) {
            const __m128 vlo = _mm_set1_ps(p.lo[i][0]), vhi = _mm_set1_ps(p.hi[i][0]);
            __m128 e = _mm_max_ps(_mm_max_ps(_mm_sub_ps(vhi, s[q]), _mm_sub_ps(s[q], vlo)), zero);
            if constexpr (OneSided) {
                const __m128 above = _mm_cmpgt_ps(vhi, s[q]);
                e = _mm_or_ps(_mm_and_ps(above, vinf), _mm_andnot_ps(above, e));
            }
            err[i][q] = e;
            best = _mm_min_ps(e, best);
        }
        // !(best <= stop) for any texel: infeasible or worse than the incumbent.
        if (_mm_movemask_ps(_mm_cmple_ps(best, vstop)) != 15) return out;
        block = _mm_max_ps(best, block);
    }
    const float block_max = max_of_lanes(block);
    out.max_err = block_max;
    const __m128 vmax = _mm_set1_ps(block_max);
    __m128d best_sq[8], best_i[8], sd[8];
    for (int q = 0; q < 4; ++q) {
        sd[2 * q] = _mm_cvtps_pd(s[q]);
        sd[2 * q + 1] = _mm_cvtps_pd(_mm_movehl_ps(s[q], s[q]));
    }
    for (int h = 0; h < 8; ++h) { best_sq[h] = _mm_set1_pd(std::numeric_limits<double>::infinity()); best_i[h] = _mm_setzero_pd(); }
    for (int i = 0; i < p.n; ++i) {
        __m128 ok[4];
        int any = 0;
        for (int q = 0; q < 4; ++q) { ok[q] = _mm_cmple_ps(err[i][q], vmax); any |= _mm_movemask_ps(ok[q]); }
        if (!any) continue; // no texel may use entry i
        const __m128d vr = _mm_set1_pd(double(p.ref[i][0])), vi = _mm_set1_pd(double(i));
        for (int h = 0; h < 8; ++h) {
            const __m128 okq = ok[h / 2];
            const __m128d allowed = _mm_castps_pd((h & 1) ? _mm_unpackhi_ps(okq, okq) : _mm_unpacklo_ps(okq, okq));
            const __m128d d = _mm_sub_pd(vr, sd[h]);
            const __m128d sq = _mm_mul_pd(d, d);
            const __m128d take = _mm_and_pd(allowed, _mm_cmplt_pd(sq, best_sq[h])); // first minimum wins
            best_sq[h] = _mm_or_pd(_mm_and_pd(take, sq), _mm_andnot_pd(take, best_sq[h]));
            best_i[h] = _mm_or_pd(_mm_and_pd(take, vi), _mm_andnot_pd(take, best_i[h]));
        }
    }
    double sq[16], bi[16];
    for (int h = 0; h < 8; ++h) { _mm_storeu_pd(sq + 2 * h, best_sq[h]); _mm_storeu_pd(bi + 2 * h, best_i[h]); }
    double total = 0;
    for (int t = 0; t < 16; ++t) { out.idx[t] = uint8_t(bi[t]); total += sq[t]; }
    out.sum_sq = total;
    return out;
}
#endif

// Whether a one-channel palette serves every texel within `stop` (the first pass of
// select_indices alone, in any texel order: a filter before the full selection).
inline bool palette_within(const Palette<1>& p, const float* src, bool one_sided, float stop) {
    for (int t = 0; t < 16; ++t) {
        const float s = src[t];
        bool ok = false;
        for (int i = 0; i < p.n && !ok; ++i) {
            if (one_sided && p.hi[i][0] > s) continue;
            const float a = p.hi[i][0] - s, b = s - p.lo[i][0];
            ok = std::max(0.0f, a > b ? a : b) <= stop;
        }
        if (!ok) return false;
    }
    return true;
}

template <int C, bool OneSided>
inline Selection select_indices_t(const Palette<C>& p, const float* src, float stop_above, float budget, double sum_stop) {
#if defined(__SSE2__)
    if constexpr (C == 1) return select_indices_scalar_t<OneSided>(p, src, stop_above); // no budget for C == 1
#endif
    Selection out;
    float block_max = 0;
    for (int t = 0; t < 16; ++t) {
        float best = std::numeric_limits<float>::infinity();
        for (int i = 0; i < p.n; ++i) best = std::min(best, entry_error_t<C, OneSided>(p, i, src + t * C));
        if (!(best <= stop_above)) return out; // infeasible or worse than the incumbent
        block_max = std::max(block_max, best);
    }
    // Each texel may use any entry within the allowance: the palette's least block max
    // error, or the budget when that is larger (then the block's max error is that of the
    // entries chosen).
    const float allowance = budget > block_max ? budget : block_max;
    float chosen_max = 0;
    double total = 0;
    // Each entry's squared error: BC1 (C == 3) in float, as its AVX2 path (bc1_eval.h: 8
    // texels a register; encoder version 8), one channel in double, as the SSE2 path above.
    using Square = std::conditional_t<C == 3, float, double>;
    for (int t = 0; t < 16; ++t) {
        const float* s = src + t * C;
        Square best_sq = std::numeric_limits<Square>::infinity();
        int best_i = 0;
        float best_e = 0;
        for (int i = 0; i < p.n; ++i) {
            const float e = entry_error_t<C, OneSided>(p, i, s);
            if (!(e <= allowance)) continue;
            Square sq = 0;
            for (int c = 0; c < C; ++c) { const Square d = Square(p.ref[i][c]) - Square(s[c]); sq += d * d; }
            if (sq < best_sq) { best_sq = sq; best_i = i; best_e = e; }
        }
        out.idx[t] = uint8_t(best_i);
        chosen_max = std::max(chosen_max, best_e);
        total += best_sq;
        // The sum only grows (squares are >= 0): past the incumbent's, the pair cannot win.
        if ((t & 3) == 3 && total > sum_stop) { out.max_err = std::numeric_limits<float>::infinity(); return out; }
    }
    out.max_err = allowance > block_max ? chosen_max : block_max;
    out.sum_sq = total;
    return out;
}

// Optimal indices for a fixed palette: minimises the block's max error, then the
// squared Reference error among index choices that keep that max. Returns
// max_err = +inf early when the max already exceeds `stop_above`. With a budget
// (C == 3 only; < 0: none) at or above that least max error, each texel takes its least
// squared error among the entries within the budget instead: optimal for better_within.
// sum_stop (C == 3 only): max_err = +inf too once the squared error, summed in texel
// order, exceeds it (the incumbent's, when a pair must beat it on the sum to win).
template <int C>
inline Selection select_indices(const Palette<C>& p, const float* src, bool one_sided,
                                float stop_above = std::numeric_limits<float>::infinity(), float budget = -1.0f,
                                double sum_stop = std::numeric_limits<double>::infinity()) {
    return one_sided ? select_indices_t<C, true>(p, src, stop_above, budget, sum_stop)
                     : select_indices_t<C, false>(p, src, stop_above, budget, sum_stop);
}

} // namespace atlas::compress::detail

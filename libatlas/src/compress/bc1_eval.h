// Internal: BC1 index selection (select_indices<3>, palette_search.h) with AVX2 on a
// channel-major palette (bc1_interval_palette_cm), the same result bit for bit: the block's max error and every texel's entry through the same float
// operations (MAXPS(a, b) is `a > b ? a : b`, MINPS likewise, as written there), the
// squared Reference error of each entry in float in the same order ((d0^2 + d1^2) + d2^2;
// 8 texels a register), the first minimum per texel, and the texels' squares summed in
// double in texel order. Run after a
// CPU check (bc1_encode.cpp); elsewhere the encoder calls select_indices itself. Tested
// against select_indices: Bc1Eval.Avx2EqualsSelectIndices.
#pragma once

#include "simd_choice.h"
#include "bc1_palette.h"
#include "palette_search.h"

#include <cstdint>
#include <limits>

#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>
#define ATLAS_BC1_AVX2 1
#endif

namespace atlas::compress::detail {

// The 16 texels of a block as channel planes (r[t], g[t], b[t]).
struct Bc1Planes {
    alignas(32) float c[3][16];
    explicit Bc1Planes(const float* rgb) {
        for (int t = 0; t < 16; ++t)
            for (int ch = 0; ch < 3; ++ch) c[ch][t] = rgb[3 * t + ch];
    }
};

#if defined(ATLAS_BC1_AVX2)
inline bool bc1_cpu_has_avx2() { return !simd_env_forbids_avx2() && __builtin_cpu_supports("avx2") != 0; }

template <bool OneSided>
__attribute__((target("avx2"))) inline Selection bc1_select_avx2(const Bc1PaletteCm& p, const Bc1Planes& s, float stop_above, float budget = -1.0f,
                                                                 double sum_stop = std::numeric_limits<double>::infinity()) {
    Selection out;
    const __m256 zero = _mm256_setzero_ps(), vinf = _mm256_set1_ps(std::numeric_limits<float>::infinity());
    const __m256 vstop = _mm256_set1_ps(stop_above);
    __m256 err[4][2], block = zero;
    for (int h = 0; h < 2; ++h) {
        const __m256 sr = _mm256_load_ps(s.c[0] + 8 * h), sg = _mm256_load_ps(s.c[1] + 8 * h), sb = _mm256_load_ps(s.c[2] + 8 * h);
        const __m256 sv[3] = {sr, sg, sb};
        __m256 best = vinf;
        for (int i = 0; i < 4; ++i) {
            __m256 e = zero, above = zero;
            for (int ch = 0; ch < 3; ++ch) {
                const __m256 lo = _mm256_set1_ps(p.lo[ch][i]), hi = _mm256_set1_ps(p.hi[ch][i]);
                const __m256 m = _mm256_max_ps(_mm256_sub_ps(hi, sv[ch]), _mm256_sub_ps(sv[ch], lo));
                e = _mm256_max_ps(m, e); // std::max(e, m) = e < m ? m : e
                if constexpr (OneSided) above = _mm256_or_ps(above, _mm256_cmp_ps(hi, sv[ch], _CMP_GT_OQ));
            }
            if constexpr (OneSided) e = _mm256_blendv_ps(e, vinf, above);
            err[i][h] = e;
            best = _mm256_min_ps(e, best); // std::min(best, e) = e < best ? e : best
        }
        // !(best <= stop) for any texel: infeasible or worse than the incumbent.
        if (_mm256_movemask_ps(_mm256_cmp_ps(best, vstop, _CMP_LE_OQ)) != 0xff) return out;
        block = _mm256_max_ps(best, block);
    }
    float bm[8];
    _mm256_storeu_ps(bm, block);
    float block_max = 0;
    for (int j = 0; j < 8; ++j) block_max = std::max(block_max, bm[j]);
    // The allowance per texel: the least block max, or the budget above it (select_indices).
    const float allowance = budget > block_max ? budget : block_max;
    // Each texel takes its first least squared error among the entries within the allowance.
    const __m256 vmaxf = _mm256_set1_ps(allowance);
    __m256 ok[4][2];
    bool usable[4];
    for (int i = 0; i < 4; ++i) {
        ok[i][0] = _mm256_cmp_ps(err[i][0], vmaxf, _CMP_LE_OQ);
        ok[i][1] = _mm256_cmp_ps(err[i][1], vmaxf, _CMP_LE_OQ);
        usable[i] = _mm256_movemask_ps(_mm256_or_ps(ok[i][0], ok[i][1])) != 0; // entries no texel may use are skipped
    }
    double total = 0;
    for (int h = 0; h < 2; ++h) {
        __m256 best_sq = vinf, best_i = zero;
        const __m256 s0 = _mm256_load_ps(s.c[0] + 8 * h), s1 = _mm256_load_ps(s.c[1] + 8 * h), s2 = _mm256_load_ps(s.c[2] + 8 * h);
        for (int i = 0; i < 4; ++i) {
            if (!usable[i]) continue;
            const __m256 d0 = _mm256_sub_ps(_mm256_set1_ps(p.ref[0][i]), s0), d1 = _mm256_sub_ps(_mm256_set1_ps(p.ref[1][i]), s1),
                         d2 = _mm256_sub_ps(_mm256_set1_ps(p.ref[2][i]), s2);
            const __m256 sq = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(d0, d0), _mm256_mul_ps(d1, d1)), _mm256_mul_ps(d2, d2));
            const __m256 take = _mm256_and_ps(ok[i][h], _mm256_cmp_ps(sq, best_sq, _CMP_LT_OQ)); // first minimum wins
            best_sq = _mm256_blendv_ps(best_sq, sq, take);
            best_i = _mm256_blendv_ps(best_i, _mm256_set1_ps(float(i)), take);
        }
        float sq[8], bi[8];
        _mm256_storeu_ps(sq, best_sq);
        _mm256_storeu_ps(bi, best_i);
        for (int j = 0; j < 8; ++j) { out.idx[8 * h + j] = uint8_t(bi[j]); total += sq[j]; } // texel order, as select_indices
        // The sum only grows (squares are >= 0): past the incumbent's, the pair cannot win.
        if (total > sum_stop) { out.max_err = std::numeric_limits<float>::infinity(); return out; }
    }
    out.sum_sq = total;
    out.max_err = block_max;
    if (allowance > block_max) { // the chosen entries' errors, as select_indices takes them
        alignas(32) float e[4][16];
        for (int i = 0; i < 4; ++i) { _mm256_store_ps(e[i], err[i][0]); _mm256_store_ps(e[i] + 8, err[i][1]); }
        float chosen = 0;
        for (int t = 0; t < 16; ++t) chosen = std::max(chosen, e[out.idx[t]][t]);
        out.max_err = chosen;
    }
    return out;
}
#else
inline bool bc1_cpu_has_avx2() { return false; }
#endif

} // namespace atlas::compress::detail

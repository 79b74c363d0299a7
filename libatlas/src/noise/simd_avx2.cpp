// AVX2 instance of the SIMD noise kernels (simd_kernels.h), run only where
// the CPU reports AVX2 (simd.cpp). Compiled with -mavx2 -mfma -ffp-contract=off
// (libatlas/CMakeLists.txt): no intrinsic here is fused, and the compiler
// may not fuse either, so the bytes equal the scalar and SSE2 paths'.
#if defined(__AVX2__)
#define ATLAS_NOISE_ISA avx2
#include "simd_kernels.h"

#include <immintrin.h>

namespace atlas::noise::detail {
namespace avx2 {
namespace {

struct Isa {
    using F = __m256;
    using V = __m256i;
    static constexpr int W = 8;

    static F fset(float v) { return _mm256_set1_ps(v); }
    static F fload(const float* p) { return _mm256_load_ps(p); }
    static void fstore(float* p, F v) { _mm256_storeu_ps(p, v); }
    static F add(F a, F b) { return _mm256_add_ps(a, b); }
    static F sub(F a, F b) { return _mm256_sub_ps(a, b); }
    static F mul(F a, F b) { return _mm256_mul_ps(a, b); }
    static F fmin(F a, F b) { return _mm256_min_ps(a, b); } // a < b ? a : b
    static F fmax(F a, F b) { return _mm256_max_ps(a, b); } // a > b ? a : b
    static F fabs(F a) { return _mm256_andnot_ps(_mm256_set1_ps(-0.0f), a); }
    static float sqrt1(float v) { return _mm_cvtss_f32(_mm_sqrt_ss(_mm_set_ss(v))); }

    static V iset(int v) { return _mm256_set1_epi32(v); }
    static V iload(const int* p) { return _mm256_load_si256(reinterpret_cast<const __m256i*>(p)); }
    static void istore(int* p, V v) { _mm256_store_si256(reinterpret_cast<__m256i*>(p), v); }
    static V iadd(V a, V b) { return _mm256_add_epi32(a, b); }
    static V isub(V a, V b) { return _mm256_sub_epi32(a, b); }
    static V iand(V a, V b) { return _mm256_and_si256(a, b); }
    static V iandnot(V a, V b) { return _mm256_andnot_si256(a, b); } // ~a & b
    static V icmpeq(V a, V b) { return _mm256_cmpeq_epi32(a, b); }
    static V icmpgt(V a, V b) { return _mm256_cmpgt_epi32(a, b); }
    static V imul(V a, V b) { return _mm256_mullo_epi32(a, b); }

    static void split(const double* u, double scale, V& c, F& f) {
        const __m256d s = _mm256_set1_pd(scale);
        __m128i ci[2];
        __m128 fi[2];
        for (int h = 0; h < 2; ++h) {
            const __m256d x = _mm256_mul_pd(_mm256_loadu_pd(u + 4 * h), s);
            const __m256d t = _mm256_floor_pd(x);
            ci[h] = _mm256_cvttpd_epi32(t);
            fi[h] = _mm256_cvtpd_ps(_mm256_sub_pd(x, t));
        }
        c = _mm256_set_m128i(ci[1], ci[0]);
        f = _mm256_set_m128(fi[1], fi[0]);
    }

    static V gather_lo32(const uint64_t* table, V idx) {
        return _mm256_i32gather_epi32(reinterpret_cast<const int*>(table), _mm256_slli_epi32(idx, 1), 4);
    }

    static void grad3(V h, F& g0, F& g1, F& g2) {
        alignas(32) static constexpr float t[3][16] = {
            {1, -1, 1, -1, 1, -1, 1, -1, 0, 0, 0, 0, 1, -1, 0, 0},
            {1, 1, -1, -1, 0, 0, 0, 0, 1, -1, 1, -1, 1, 1, -1, -1},
            {0, 0, 0, 0, 1, 1, -1, -1, 1, 1, -1, -1, 0, 0, 1, -1}};
        const F hi = _mm256_castsi256_ps(_mm256_slli_epi32(h, 28)); // sign bit = bit 3 of h
        F* g[3] = {&g0, &g1, &g2};
        for (int c = 0; c < 3; ++c)
            *g[c] = _mm256_blendv_ps(_mm256_permutevar8x32_ps(_mm256_load_ps(t[c]), h),
                                     _mm256_permutevar8x32_ps(_mm256_load_ps(t[c] + 8), h), hi);
    }

    template <bool Min>
    static void combine(F a1, F a2, F b1, F b2, F& c1, F& c2) {
        if constexpr (Min) {
            c1 = _mm256_min_ps(a1, b1);
            c2 = _mm256_min_ps(_mm256_max_ps(a1, b1), _mm256_min_ps(a2, b2));
        } else {
            c1 = _mm256_max_ps(a1, b1);
            c2 = _mm256_max_ps(_mm256_min_ps(a1, b1), _mm256_max_ps(a2, b2));
        }
    }
    template <bool Min>
    static void reduce2(F a1, F a2, float& r1, float& r2) {
        combine<Min>(a1, a2, _mm256_permute2f128_ps(a1, a1, 1), _mm256_permute2f128_ps(a2, a2, 1), a1, a2);
        combine<Min>(a1, a2, _mm256_shuffle_ps(a1, a1, _MM_SHUFFLE(1, 0, 3, 2)), _mm256_shuffle_ps(a2, a2, _MM_SHUFFLE(1, 0, 3, 2)), a1, a2);
        combine<Min>(a1, a2, _mm256_shuffle_ps(a1, a1, _MM_SHUFFLE(2, 3, 0, 1)), _mm256_shuffle_ps(a2, a2, _MM_SHUFFLE(2, 3, 0, 1)), a1, a2);
        r1 = _mm256_cvtss_f32(a1);
        r2 = _mm256_cvtss_f32(a2);
    }
    static void reduce_min2(F a1, F a2, float& r1, float& r2) { reduce2<true>(a1, a2, r1, r2); }
    static void reduce_max2(F a1, F a2, float& r1, float& r2) { reduce2<false>(a1, a2, r1, r2); }
};

} // namespace
} // namespace avx2

const SimdKernels& avx2_kernels() { return avx2::Kernels<avx2::Isa>::table(); }

} // namespace atlas::noise::detail
#endif

// AVX-512 instance of the SIMD gradient kernel (simd_kernels.h), run only
// where the CPU reports AVX-512F (simd.cpp): sixteen lanes. Compiled with
// -mavx512f -mfma -ffp-contract=off (libatlas/CMakeLists.txt): no intrinsic
// here is fused and the compiler may not fuse either, so the bytes equal the
// scalar, SSE2 and AVX2 paths'. Only AVX-512F instructions are used (masks
// turned back into lane vectors with a masked move, not AVX-512DQ's movm).
#if defined(__AVX512F__)
// GCC 12's avx512fintrin.h starts many intrinsics from _mm512_undefined_*()
// and then warns that the value "may be used uninitialized" where inlined
// (a known false positive of the header): silenced for this file only.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#define ATLAS_NOISE_ISA avx512
#include "simd_kernels.h"

#include <immintrin.h>

namespace atlas::noise::detail {
namespace avx512 {
namespace {

// What gradient3 reads of the traits (the cellular kernels, which also need
// fload, fabs, sqrt1 and the reductions, stay on AVX2's: avx512_kernels below).
struct Isa {
    using F = __m512;
    using V = __m512i;
    static constexpr int W = 16;

    static F fset(float v) { return _mm512_set1_ps(v); }
    static void fstore(float* p, F v) { _mm512_storeu_ps(p, v); }
    static F add(F a, F b) { return _mm512_add_ps(a, b); }
    static F sub(F a, F b) { return _mm512_sub_ps(a, b); }
    static F mul(F a, F b) { return _mm512_mul_ps(a, b); }
    static F fmin(F a, F b) { return _mm512_min_ps(a, b); } // a < b ? a : b, as MINPS
    static F fmax(F a, F b) { return _mm512_max_ps(a, b); } // a > b ? a : b

    static V iset(int v) { return _mm512_set1_epi32(v); }
    static V iload(const int* p) { return _mm512_load_si512(p); }
    static void istore(int* p, V v) { _mm512_store_si512(p, v); }
    static V iadd(V a, V b) { return _mm512_add_epi32(a, b); }
    static V isub(V a, V b) { return _mm512_sub_epi32(a, b); }
    static V iand(V a, V b) { return _mm512_and_si512(a, b); }
    static V iandnot(V a, V b) { return _mm512_andnot_si512(a, b); } // ~a & b
    static V lanes(__mmask16 m) { return _mm512_maskz_mov_epi32(m, _mm512_set1_epi32(-1)); }
    static V icmpeq(V a, V b) { return lanes(_mm512_cmpeq_epi32_mask(a, b)); }
    static V icmpgt(V a, V b) { return lanes(_mm512_cmpgt_epi32_mask(a, b)); }
    static V imul(V a, V b) { return _mm512_mullo_epi32(a, b); }

    static void split(const double* u, double scale, V& c, F& f) {
        const __m512d s = _mm512_set1_pd(scale);
        __m256i ci[2];
        __m256 fi[2];
        for (int h = 0; h < 2; ++h) {
            const __m512d x = _mm512_mul_pd(_mm512_loadu_pd(u + 8 * h), s);
            const __m512d t = _mm512_roundscale_pd(x, _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC); // floor, exact
            ci[h] = _mm512_cvttpd_epi32(t);
            fi[h] = _mm512_cvtpd_ps(_mm512_sub_pd(x, t));
        }
        c = _mm512_inserti64x4(_mm512_castsi256_si512(ci[0]), ci[1], 1);
        f = _mm512_castpd_ps(_mm512_insertf64x4(_mm512_castps_pd(_mm512_castps256_ps512(fi[0])), _mm256_castps_pd(fi[1]), 1));
    }

    static V gather_lo32(const uint64_t* table, V idx) { return _mm512_i32gather_epi32(_mm512_slli_epi32(idx, 1), table, 4); }

    // kGrad3's 16 rows per component: one permute over the hash's low 4 bits.
    static void grad3(V h, F& g0, F& g1, F& g2) {
        alignas(64) static constexpr float t[3][16] = {
            {1, -1, 1, -1, 1, -1, 1, -1, 0, 0, 0, 0, 1, -1, 0, 0},
            {1, 1, -1, -1, 0, 0, 0, 0, 1, -1, 1, -1, 1, 1, -1, -1},
            {0, 0, 0, 0, 1, 1, -1, -1, 1, 1, -1, -1, 0, 0, 1, -1}};
        g0 = _mm512_permutexvar_ps(h, _mm512_load_ps(t[0]));
        g1 = _mm512_permutexvar_ps(h, _mm512_load_ps(t[1]));
        g2 = _mm512_permutexvar_ps(h, _mm512_load_ps(t[2]));
    }
};

} // namespace
} // namespace avx512

// Gradient noise in 16 lanes (1.8-1.9x AVX2's rate); Worley and Alligator stay
// on AVX2's 8 lanes, which measured 6-15% faster than 16 (a sample's 27
// neighbours take two 16-lane passes and a four-step reduction against four
// 8-lane passes and three steps; docs/PERFORMANCE.md, 2026-12-08).
const SimdKernels& avx512_kernels() {
    static const SimdKernels k = [] {
        SimdKernels t = avx2_kernels();
        t.gradient3 = &avx512::Kernels<avx512::Isa>::gradient3;
        return t;
    }();
    return k;
}

} // namespace atlas::noise::detail
#endif

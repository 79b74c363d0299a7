// SSE2 (x86-64 baseline) instance of the SIMD noise kernels (simd_kernels.h).
// Compiled with -ffp-contract=off (libatlas/CMakeLists.txt).
#if defined(__SSE2__)
#define ATLAS_NOISE_ISA sse2
#include "simd_kernels.h"

#include <emmintrin.h>

namespace atlas::noise::detail {
namespace sse2 {
namespace {

struct Isa {
    using F = __m128;
    using V = __m128i;
    static constexpr int W = 4;

    static F fset(float v) { return _mm_set1_ps(v); }
    static F fload(const float* p) { return _mm_load_ps(p); }
    static void fstore(float* p, F v) { _mm_storeu_ps(p, v); }
    static F add(F a, F b) { return _mm_add_ps(a, b); }
    static F sub(F a, F b) { return _mm_sub_ps(a, b); }
    static F mul(F a, F b) { return _mm_mul_ps(a, b); }
    static F fmin(F a, F b) { return _mm_min_ps(a, b); } // a < b ? a : b
    static F fmax(F a, F b) { return _mm_max_ps(a, b); } // a > b ? a : b
    static F fabs(F a) { return _mm_andnot_ps(_mm_set1_ps(-0.0f), a); }
    static float sqrt1(float v) { return _mm_cvtss_f32(_mm_sqrt_ss(_mm_set_ss(v))); }

    static V iset(int v) { return _mm_set1_epi32(v); }
    static V iload(const int* p) { return _mm_load_si128(reinterpret_cast<const __m128i*>(p)); }
    static void istore(int* p, V v) { _mm_store_si128(reinterpret_cast<__m128i*>(p), v); }
    static V iadd(V a, V b) { return _mm_add_epi32(a, b); }
    static V isub(V a, V b) { return _mm_sub_epi32(a, b); }
    static V iand(V a, V b) { return _mm_and_si128(a, b); }
    static V iandnot(V a, V b) { return _mm_andnot_si128(a, b); } // ~a & b
    static V icmpeq(V a, V b) { return _mm_cmpeq_epi32(a, b); }
    static V icmpgt(V a, V b) { return _mm_cmpgt_epi32(a, b); }
    static V imul(V a, V b) {
        const __m128i e = _mm_mul_epu32(a, b), o = _mm_mul_epu32(_mm_srli_si128(a, 4), _mm_srli_si128(b, 4));
        return _mm_unpacklo_epi32(_mm_shuffle_epi32(e, _MM_SHUFFLE(0, 0, 2, 0)), _mm_shuffle_epi32(o, _MM_SHUFFLE(0, 0, 2, 0)));
    }

    // floor in double (truncation, one down where it rounded up), u - floor(u), to float.
    static void split(const double* u, double scale, V& c, F& f) {
        const __m128d s = _mm_set1_pd(scale), one = _mm_set1_pd(1.0);
        __m128i ci[2];
        __m128 fi[2];
        for (int h = 0; h < 2; ++h) {
            const __m128d x = _mm_mul_pd(_mm_loadu_pd(u + 2 * h), s);
            __m128d t = _mm_cvtepi32_pd(_mm_cvttpd_epi32(x));
            t = _mm_sub_pd(t, _mm_and_pd(_mm_cmpgt_pd(t, x), one));
            ci[h] = _mm_cvttpd_epi32(t);
            fi[h] = _mm_cvtpd_ps(_mm_sub_pd(x, t));
        }
        c = _mm_unpacklo_epi64(ci[0], ci[1]);
        f = _mm_movelh_ps(fi[0], fi[1]);
    }

    static V gather_lo32(const uint64_t* table, V idx) {
        alignas(16) int i[4];
        istore(i, idx);
        return _mm_setr_epi32(int(uint32_t(table[i[0]])), int(uint32_t(table[i[1]])), int(uint32_t(table[i[2]])),
                              int(uint32_t(table[i[3]])));
    }

    static void grad3(V h, F& g0, F& g1, F& g2) {
        alignas(16) int i[4];
        istore(i, h);
        __m128 r0 = _mm_load_ps(kGradRows[i[0]]), r1 = _mm_load_ps(kGradRows[i[1]]), r2 = _mm_load_ps(kGradRows[i[2]]),
               r3 = _mm_load_ps(kGradRows[i[3]]);
        _MM_TRANSPOSE4_PS(r0, r1, r2, r3);
        g0 = r0;
        g1 = r1;
        g2 = r2;
    }

    // The two smallest (largest) of the lanes' pairs (a1 <= a2 per lane).
    static void reduce_min2(F a1, F a2, float& r1, float& r2) {
        F b1 = _mm_movehl_ps(a1, a1), b2 = _mm_movehl_ps(a2, a2);
        F c1 = _mm_min_ps(a1, b1), c2 = _mm_min_ps(_mm_max_ps(a1, b1), _mm_min_ps(a2, b2));
        b1 = _mm_shuffle_ps(c1, c1, _MM_SHUFFLE(1, 1, 1, 1));
        b2 = _mm_shuffle_ps(c2, c2, _MM_SHUFFLE(1, 1, 1, 1));
        r1 = _mm_cvtss_f32(_mm_min_ps(c1, b1));
        r2 = _mm_cvtss_f32(_mm_min_ps(_mm_max_ps(c1, b1), _mm_min_ps(c2, b2)));
    }
    static void reduce_max2(F a1, F a2, float& r1, float& r2) {
        F b1 = _mm_movehl_ps(a1, a1), b2 = _mm_movehl_ps(a2, a2);
        F c1 = _mm_max_ps(a1, b1), c2 = _mm_max_ps(_mm_min_ps(a1, b1), _mm_max_ps(a2, b2));
        b1 = _mm_shuffle_ps(c1, c1, _MM_SHUFFLE(1, 1, 1, 1));
        b2 = _mm_shuffle_ps(c2, c2, _MM_SHUFFLE(1, 1, 1, 1));
        r1 = _mm_cvtss_f32(_mm_max_ps(c1, b1));
        r2 = _mm_cvtss_f32(_mm_max_ps(_mm_min_ps(c1, b1), _mm_max_ps(c2, b2)));
    }
};

} // namespace
} // namespace sse2

const SimdKernels& sse2_kernels() { return sse2::Kernels<sse2::Isa>::table(); }

} // namespace atlas::noise::detail
#endif

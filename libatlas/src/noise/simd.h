// Internal: the SIMD kernels (3D gradient, Worley, Alligator octaves) and
// their dispatch. Every path (scalar in engine.cpp, SSE2 in simd_sse2.cpp,
// AVX2 in simd_avx2.cpp, AVX-512 in simd_avx512.cpp) performs the same IEEE operations in the same order
// on every sample, so all of them write the same bytes (tests/noise/
// simd_test.cpp). The ISA translation units see only plain data (LatticeView):
// they call no inline function that another translation unit also emits, so
// the linker can never pick an AVX2 copy for the baseline code.
#pragma once

#include "atlas/noise/noise_spec.h"
#include "atlas/noise/simd.h"

#include <cstddef>
#include <cstdint>

namespace atlas::noise::detail {

// A 3D lattice as plain data. table: the tabulated bits (x fastest), or
// nullptr, then bits(lattice, x, y, z) computes them (out of line, baseline).
struct LatticeView {
    const uint64_t* table = nullptr;
    int px = 1, py = 1, pz = 1;
    const void* lattice = nullptr;
    uint64_t (*bits)(const void* lattice, int x, int y, int z) = nullptr;
    // A hashed lattice's cell corners (corner_bits3 of lattice.h, & 15), compiled
    // with the baseline flags like bits: no inline code is shared with the ISA files.
    void (*corners)(const void* lattice, const int (&xs)[2], const int (&ys)[2], const int (&zs)[2], int first_i, int (&out)[8]) = nullptr;
};

// One ISA's kernels. u[a][i] * scale is sample i's lattice coordinate on axis
// a (u in [0, base period), scale the octave's frequency); n samples; out[i]
// receives the same value engine.cpp's scalar octave computes.
struct SimdKernels {
    void (*gradient3)(const LatticeView& L, const double* const* u, size_t n, double scale, float* out);
    void (*worley3[3])(const LatticeView& L, const double* const* u, size_t n, double scale, float jitter, WorleyFeature f,
                       float* out); // by WorleyMetric
    void (*alligator3)(const LatticeView& L, const double* const* u, size_t n, double scale, float inv_r2, float* out);
};

// nullptr for the scalar path. Throws atlas::Error when ATLAS_SIMD names an
// unknown or unsupported path.
const SimdKernels* active_kernels();

const SimdKernels& sse2_kernels();
const SimdKernels& avx2_kernels();
const SimdKernels& avx512_kernels();

} // namespace atlas::noise::detail

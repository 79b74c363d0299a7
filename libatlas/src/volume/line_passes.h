// Internal: run a 1D operation over every grid line along one axis, in
// parallel, with cache-friendly gathering of strided lines. Each line is an
// independent computation, so results do not depend on the thread count.
#pragma once

#include "atlas/core/math.h"
#include "atlas/core/parallel.h"

#include <algorithm>
#include <cstddef>
#include <vector>

namespace atlas::volume::detail {

// op(const float* in, float* out, int n, size_t base): in and out are contiguous copies of
// one line of `src` / `dst` (out's contents on entry are unspecified; op
// must write all n values).
// base is the flat grid index of the line's first sample.
// src and dst may be the same array.
template <typename Op>
void for_each_line(Vec3i res, int axis, const float* src, float* dst, Op op) {
    const size_t stride[3] = {1, size_t(res[0]), size_t(res[0]) * size_t(res[1])};
    const int n = res[axis];
    if (axis == 0) {
        // One task per z-slice; each line is written by exactly one task.
        parallel_for_index(res[2], [&](int z) {
            std::vector<float> in(static_cast<size_t>(n)), out(static_cast<size_t>(n));
            for (int y = 0; y < res[1]; ++y) {
                const size_t base = size_t(z) * stride[2] + size_t(y) * stride[1];
                std::copy(src + base, src + base + size_t(n), in.begin());
                op(in.data(), out.data(), n, base);
                std::copy(out.begin(), out.end(), dst + base);
            }
        });
        return;
    }
    // Strided lines: gather kBlock neighbouring x-columns at once so every
    // memory row read is kBlock contiguous floats.
    constexpr int kBlock = 16;
    const int other = axis == 1 ? 2 : 1; // the axis we parallelise over
    parallel_for_index(res[other], [&](int w) {
        std::vector<float> bin(size_t(n) * kBlock), bout(size_t(n) * kBlock);
        std::vector<float> in(static_cast<size_t>(n)), out(static_cast<size_t>(n));
        for (int x0 = 0; x0 < res[0]; x0 += kBlock) {
            const int bw = std::min(kBlock, res[0] - x0);
            const size_t base = size_t(w) * stride[other] + size_t(x0);
            for (int i = 0; i < n; ++i) {
                const size_t o = base + size_t(i) * stride[axis];
                for (int k = 0; k < bw; ++k) {
                    bin[size_t(i) * kBlock + size_t(k)] = src[o + size_t(k)];
                }
            }
            for (int k = 0; k < bw; ++k) {
                for (int i = 0; i < n; ++i) in[size_t(i)] = bin[size_t(i) * kBlock + size_t(k)];
                op(in.data(), out.data(), n, base + size_t(k));
                for (int i = 0; i < n; ++i) bout[size_t(i) * kBlock + size_t(k)] = out[size_t(i)];
            }
            for (int i = 0; i < n; ++i) {
                const size_t o = base + size_t(i) * stride[axis];
                for (int k = 0; k < bw; ++k) dst[o + size_t(k)] = bout[size_t(i) * kBlock + size_t(k)];
            }
        }
    });
}

} // namespace atlas::volume::detail

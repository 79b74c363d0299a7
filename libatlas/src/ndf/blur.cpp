// Separable Gaussian blur with clamped or wrapped edges.
#include "atlas/ndf/operators.h"

#include "atlas/core/error.h"

#include "atlas/core/parallel.h"

#include <cmath>

namespace atlas::ndf {

namespace {
int wrap_index(int i, int n, WrapMode w) {
    if (w == WrapMode::Clamp) return std::clamp(i, 0, n - 1);
    const int m = i % n;
    return m < 0 ? m + n : m;
}
} // namespace

Field2D blur(const Field2D& in, double sigma, WrapMode wrap, const MemoryBudget* budget) {
    if (!(sigma >= 0) || !std::isfinite(sigma) || sigma > 4096) throw Error("blur: 'sigma' must be in [0, 4096] texels");
    Field2D out(in.resolution(), in.channels(), in.bounds(), in.channel_names(), budget);
    const int rad = int(std::ceil(3 * sigma));
    std::vector<float> k(size_t(2 * rad + 1));
    double sum = 0;
    for (int i = -rad; i <= rad; ++i) sum += (k[size_t(i + rad)] = sigma > 0 ? float(std::exp(-0.5 * i * i / (sigma * sigma))) : 1.0f);
    for (auto& v : k) v = float(v / sum);
    const int w = in.width(), h = in.height();
    Field2D tmp(in.resolution(), 1, in.bounds(), {}, budget);
    // Each output is sum_i k[i] * src[i] accumulated in float in tap order
    // i = -rad..rad, as the direct form; the passes only change the memory
    // walk: rows through a padded copy (no per-tap wrap), columns as whole
    // rows scaled and added (contiguous, vectorisable). Same bytes.
    for (int c = 0; c < in.channels(); ++c) {
        auto src = in.channel(c);
        auto mid = tmp.channel(0);
        auto dst = out.channel(c);
        parallel_for_index(h, [&](int y) {
            std::vector<float> pad(size_t(w + 2 * rad));
            const float* row = src.data() + in.index(0, y);
            for (int x = -rad; x < w + rad; ++x) pad[size_t(x + rad)] = row[wrap_index(x, w, wrap)];
            float* m = mid.data() + in.index(0, y);
            for (int x = 0; x < w; ++x) {
                float acc = 0;
                const float* p = pad.data() + x;
                for (int i = 0; i <= 2 * rad; ++i) acc += k[size_t(i)] * p[i];
                m[x] = acc;
            }
        });
        parallel_for_index(h, [&](int y) {
            float* d = dst.data() + in.index(0, y);
            std::fill(d, d + w, 0.0f);
            for (int i = -rad; i <= rad; ++i) {
                const float kk = k[size_t(i + rad)];
                const float* m = mid.data() + in.index(0, wrap_index(y + i, h, wrap));
                for (int x = 0; x < w; ++x) d[x] += kk * m[x];
            }
        });
    }
    return out;
}

} // namespace atlas::ndf

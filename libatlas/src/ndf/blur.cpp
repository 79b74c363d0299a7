// Separable Gaussian blur with clamped or wrapped edges.
#include "atlas/ndf/operators.h"

#include "atlas/core/error.h"

#include <tbb/parallel_for.h>

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
    for (int c = 0; c < in.channels(); ++c) {
        auto src = in.channel(c);
        auto mid = tmp.channel(0);
        auto dst = out.channel(c);
        tbb::parallel_for(0, h, [&](int y) {
            for (int x = 0; x < w; ++x) {
                float s = 0;
                for (int i = -rad; i <= rad; ++i) s += k[size_t(i + rad)] * src[in.index(wrap_index(x + i, w, wrap), y)];
                mid[in.index(x, y)] = s;
            }
        });
        tbb::parallel_for(0, h, [&](int y) {
            for (int x = 0; x < w; ++x) {
                float s = 0;
                for (int i = -rad; i <= rad; ++i) s += k[size_t(i + rad)] * mid[in.index(x, wrap_index(y + i, h, wrap))];
                dst[in.index(x, y)] = s;
            }
        });
    }
    return out;
}

} // namespace atlas::ndf

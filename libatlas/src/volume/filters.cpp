// Separable smoothing and grayscale morphology.
#include "atlas/core/error.h"
#include "atlas/core/memory.h"
#include "atlas/volume/edit.h"
#include "line_passes.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace atlas::volume {
namespace {

template <typename LineOp>
Field3D separable(const Field3D& f, const MemoryBudget* budget, LineOp op) {
    if (budget) budget->check(f.byte_size() * 2, "filter: output and scratch");
    Field3D out = f;
    for (int c = 0; c < out.channels(); ++c) {
        float* d = out.channel(c).data();
        for (int a = 0; a < 3; ++a) detail::for_each_line(f.resolution(), a, d, d, [&](const float* in, float* o, int n, size_t) { op(in, o, n); });
    }
    return out;
}

} // namespace

Field3D smooth(const Field3D& f, double sigma, const MemoryBudget* budget) {
    if (!(sigma >= 0) || !std::isfinite(sigma) || sigma > 1000) throw Error("smooth: sigma must be in [0, 1000] voxels");
    if (sigma == 0) return f;
    const int r = int(std::ceil(3 * sigma));
    std::vector<double> k(size_t(2 * r + 1));
    double sum = 0;
    for (int i = -r; i <= r; ++i) sum += k[size_t(i + r)] = std::exp(-0.5 * i * i / (sigma * sigma));
    for (double& v : k) v /= sum;
    return separable(f, budget, [&](const float* in, float* o, int n) {
        for (int i = 0; i < n; ++i) {
            double acc = 0;
            for (int j = -r; j <= r; ++j) acc += k[size_t(j + r)] * in[std::clamp(i + j, 0, n - 1)];
            o[i] = float(acc);
        }
    });
}

Field3D dilate(const Field3D& f, int r, const MemoryBudget* budget) {
    if (r < 0 || r > 1000) throw Error("dilate: radius must be in [0, 1000] voxels");
    return separable(f, budget, [&](const float* in, float* o, int n) {
        for (int i = 0; i < n; ++i) o[i] = *std::max_element(in + std::max(0, i - r), in + std::min(n, i + r + 1));
    });
}

Field3D erode(const Field3D& f, int r, const MemoryBudget* budget) {
    if (r < 0 || r > 1000) throw Error("erode: radius must be in [0, 1000] voxels");
    return separable(f, budget, [&](const float* in, float* o, int n) {
        for (int i = 0; i < n; ++i) o[i] = *std::min_element(in + std::max(0, i - r), in + std::min(n, i + r + 1));
    });
}

} // namespace atlas::volume

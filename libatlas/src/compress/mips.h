// Internal: mip reduction of normalized planes (box average, or min for one-sided).
#pragma once

#include "atlas/core/field.h"

#include <algorithm>
#include <vector>

namespace atlas::compress::detail {

// One level: planes[layer][channel], x fastest, then y, then z. Planes are field
// channels' storage (not zero-filled, large ones reused): every texel is written.
using Plane = atlas::detail::ChannelData;
struct LevelData {
    int w = 1, h = 1, d = 1;
    std::vector<std::vector<Plane>> planes;
};

// The next level: size max(1, n/2) per axis (z only for volumes). Output texel i
// covers inputs 2i and 2i+1, and the last one also covers a leftover odd input,
// so every input texel is covered. use_min: the minimum of the covered texels
// (conservative for one-sided bounds), else their mean.
inline LevelData reduce_level(const LevelData& in, bool volume, bool use_min) {
    LevelData out;
    out.w = std::max(1, in.w / 2);
    out.h = std::max(1, in.h / 2);
    out.d = volume ? std::max(1, in.d / 2) : 1;
    auto span = [](int i, int n_out, int n_in, int& a, int& b) {
        a = std::min(2 * i, n_in - 1);
        b = (i == n_out - 1) ? n_in - 1 : std::min(2 * i + 1, n_in - 1);
    };
    out.planes.resize(in.planes.size());
    for (size_t l = 0; l < in.planes.size(); ++l) {
        out.planes[l].resize(in.planes[l].size());
        for (size_t c = 0; c < in.planes[l].size(); ++c) {
            const auto& src = in.planes[l][c];
            auto& dst = out.planes[l][c];
            dst.resize(size_t(out.w) * size_t(out.h) * size_t(out.d)); // every texel written below
            for (int z = 0; z < out.d; ++z) {
                int z0, z1;
                span(z, out.d, in.d, z0, z1);
                for (int y = 0; y < out.h; ++y) {
                    int y0, y1;
                    span(y, out.h, in.h, y0, y1);
                    for (int x = 0; x < out.w; ++x) {
                        int x0, x1;
                        span(x, out.w, in.w, x0, x1);
                        double sum = 0;
                        float mn = src[(size_t(z0) * size_t(in.h) + size_t(y0)) * size_t(in.w) + size_t(x0)];
                        int n = 0;
                        for (int zz = z0; zz <= z1; ++zz)
                            for (int yy = y0; yy <= y1; ++yy)
                                for (int xx = x0; xx <= x1; ++xx) {
                                    const float v = src[(size_t(zz) * size_t(in.h) + size_t(yy)) * size_t(in.w) + size_t(xx)];
                                    sum += v;
                                    mn = std::min(mn, v);
                                    ++n;
                                }
                        dst[(size_t(z) * size_t(out.h) + size_t(y)) * size_t(out.w) + size_t(x)] = use_min ? mn : float(sum / n);
                    }
                }
            }
        }
    }
    return out;
}

} // namespace atlas::compress::detail

// Moving, rotating, scaling and squashing clouds by inverse-mapped trilinear resampling.
#include "atlas/core/error.h"
#include "atlas/core/memory.h"
#include "atlas/volume/edit.h"

#include "atlas/core/parallel.h"
#include "occupied_span.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace atlas::volume {

float sample_or(const Field3D& f, int c, Vec3d p, float outside) {
    const Box3d& b = f.bounds();
    for (int a = 0; a < 3; ++a)
        if (!(p[a] >= b.min[a] && p[a] <= b.max[a])) return outside;
    return f.sample_world(c, p, WrapMode::Clamp);
}

Field3D transform_field(const Field3D& src, const CloudTransform& t, Vec3i res, Box3d bounds, const MemoryBudget* budget) {
    for (int a = 0; a < 3; ++a)
        if (!(t.scale[a] > 0) || !std::isfinite(t.scale[a])) throw Error("transform: scale must be finite and > 0 on every axis");
    if (!(t.squash > 0) || !std::isfinite(t.squash)) throw Error("transform: squash must be finite and > 0");
    for (int a = 0; a < 3; ++a)
        if (!std::isfinite(t.translate[a]) || !std::isfinite(t.rotate_deg[a]) || !std::isfinite(t.pivot[a]))
            throw Error("transform: translate, rotate and pivot must be finite");
    // Inverse: p = pivot + S^-1 R^T (p' - pivot - translate).
    const double d2r = std::numbers::pi / 180;
    const double cx = std::cos(t.rotate_deg[0] * d2r), sx = std::sin(t.rotate_deg[0] * d2r);
    const double cy = std::cos(t.rotate_deg[1] * d2r), sy = std::sin(t.rotate_deg[1] * d2r);
    const double cz = std::cos(t.rotate_deg[2] * d2r), sz = std::sin(t.rotate_deg[2] * d2r);
    // R = Rz Ry Rx
    const double R[3][3] = {{cz * cy, cz * sy * sx - sz * cx, cz * sy * cx + sz * sx},
                            {sz * cy, sz * sy * sx + cz * cx, sz * sy * cx - cz * sx},
                            {-sy, cy * sx, cy * cx}};
    const double sq_xy = 1 / std::sqrt(t.squash);
    const Vec3d S{{t.scale[0] * sq_xy, t.scale[1] * sq_xy, t.scale[2] * t.squash}};
    Field3D out(res, src.channels(), bounds, src.channel_names(), budget);
    // A cloud fills a small part of its grid: a point whose trilinear taps all lie
    // outside the source's occupied voxels (any bits but +0) samples +0, which `out`
    // holds already, so it is not sampled (the same bytes).
    const Vec3i n = src.resolution();
    Vec3i lo = n, hi{{-1, -1, -1}};
    for (int c = 0; c < src.channels(); ++c) {
        const auto ch = src.channel(c);
        for (int z = 0; z < n[2]; ++z)
            for (int y = 0; y < n[1]; ++y) {
                const float* row = ch.data() + src.index(0, y, z);
                const auto [x0, x1] = detail::occupied_span(row, n[0]);
                if (x0 == x1) continue;
                lo = {{std::min(lo[0], x0), std::min(lo[1], y), std::min(lo[2], z)}};
                hi = {{std::max(hi[0], x1 - 1), std::max(hi[1], y), std::max(hi[2], z)}};
            }
    }
    if (hi[0] < 0) return out; // nothing but +0
    const Vec3d h = src.voxel_size();
    // Voxel coordinate u (centres at i + 0.5) has taps floor(u - 0.5) and one more:
    // both below lo when u < lo - 0.5 and both above hi when u >= hi + 1.5; the test keeps
    // half a voxel more margin on each side.
    auto occupied = [&](const Vec3d& p) {
        for (int a = 0; a < 3; ++a) {
            const double u = (p[a] - src.bounds().min[a]) / h[a];
            if (!(u >= lo[a] - 1.0 && u < hi[a] + 2.0)) return false;
        }
        return true;
    };
    parallel_for_index(res[2], [&](int z) {
        for (int y = 0; y < res[1]; ++y)
            for (int x = 0; x < res[0]; ++x) {
                const Vec3d q = out.voxel_center(x, y, z) - t.pivot - t.translate;
                Vec3d p;
                for (int i = 0; i < 3; ++i) p[i] = (R[0][i] * q[0] + R[1][i] * q[1] + R[2][i] * q[2]) / S[i] + t.pivot[i];
                if (!occupied(p)) continue;
                for (int c = 0; c < src.channels(); ++c) out.at(c, x, y, z) = sample_or(src, c, p);
            }
    });
    return out;
}

} // namespace atlas::volume

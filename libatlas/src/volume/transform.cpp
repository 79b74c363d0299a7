// Moving, rotating, scaling and squashing clouds by inverse-mapped trilinear resampling.
#include "atlas/core/error.h"
#include "atlas/core/memory.h"
#include "atlas/volume/edit.h"

#include "atlas/core/parallel.h"

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
    parallel_for_index(res[2], [&](int z) {
        for (int y = 0; y < res[1]; ++y)
            for (int x = 0; x < res[0]; ++x) {
                const Vec3d q = out.voxel_center(x, y, z) - t.pivot - t.translate;
                Vec3d p;
                for (int i = 0; i < 3; ++i) p[i] = (R[0][i] * q[0] + R[1][i] * q[1] + R[2][i] * q[2]) / S[i] + t.pivot[i];
                for (int c = 0; c < src.channels(); ++c) out.at(c, x, y, z) = sample_or(src, c, p);
            }
    });
    return out;
}

} // namespace atlas::volume

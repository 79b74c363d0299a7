// Closest-point propagation from the exact band (closest_point_flood.h).
#include "closest_point_flood.h"

#include <algorithm>
#include <cmath>

namespace atlas::volume::detail {

uint64_t flood_closest_points(float* out, Vec3i res, Box3d bounds, const std::vector<ClosestPointSeed>& seeds, double tau_voxels) {
    if (seeds.empty()) return 0;
    const int nx = res[0], ny = res[1];
    const size_t sxy = size_t(nx) * size_t(ny);
    Vec3d h;
    for (int a = 0; a < 3; ++a) h[a] = (bounds.max[a] - bounds.min[a]) / res[a];
    const double tau = tau_voxels * std::min({h[0], h[1], h[2]});
    // The queue holds a voxel and the index of its point (the seeds' points, in order):
    // 16 bytes an entry instead of 32.
    struct Item {
        uint64_t voxel;
        uint32_t point;
    };
    std::vector<Item> queue;
    queue.reserve(seeds.size() * 4);
    for (size_t i = 0; i < seeds.size(); ++i) queue.push_back({seeds[i].voxel, uint32_t(i)});
    uint64_t lowered = 0;
    for (size_t head = 0; head < queue.size(); ++head) {
        const Item it = queue[head];
        const Vec3d& c = seeds[it.point].point;
        const int at[3] = {int(it.voxel % size_t(nx)), int(it.voxel / size_t(nx) % size_t(ny)), int(it.voxel / sxy)};
        // Squared offsets from c of the voxel's and its neighbours' centres, per axis
        // (k = step + 1), by Field3D::voxel_center's arithmetic, summed as x + (y + z):
        // the same value whichever voxel computes it.
        double sq[3][3];
        for (int a = 0; a < 3; ++a)
            for (int k = 0; k < 3; ++k) {
                const double o = bounds.min[a] + (at[a] + k - 1 + 0.5) * h[a] - c[a];
                sq[a][k] = o * o;
            }
        // A voxel lowered again (by another point) since it was queued carries the newer
        // point only (seeds, whose value came from the band's arithmetic, always carry theirs).
        if (head >= seeds.size() && std::abs(out[it.voxel]) != float(std::sqrt(sq[0][1] + (sq[1][1] + sq[2][1])))) continue;
        // The neighbours inside the grid (the voxel itself is never lowered: tau > 0 or
        // the rounding test below).
        int lo[3], hi[3];
        for (int a = 0; a < 3; ++a) {
            lo[a] = at[a] > 0 ? 0 : 1;
            hi[a] = at[a] + 1 < res[a] ? 2 : 1;
        }
        for (int kz = lo[2]; kz <= hi[2]; ++kz)
            for (int ky = lo[1]; ky <= hi[1]; ++ky) {
                const double syz = sq[1][ky] + sq[2][kz];
                const uint64_t row = it.voxel + uint64_t(int64_t(ky - 1) * nx + int64_t(kz - 1) * int64_t(sxy)) - 1;
                for (int kx = lo[0]; kx <= hi[0]; ++kx) {
                    float& v = out[row + uint64_t(kx)];
                    const double limit = double(std::abs(v)) - tau;
                    const double d2 = sq[0][kx] + syz;
                    // Rarely true: one branch.
                    if (!((limit > 0) & (d2 < limit * limit))) continue;
                    const float d = float(std::sqrt(d2));
                    if (!(d < std::abs(v))) continue; // rounded up to the old value: no progress (tau 0)
                    v = std::copysign(d, v);
                    queue.push_back({row + uint64_t(kx), it.point});
                    ++lowered;
                }
            }
    }
    return lowered;
}

} // namespace atlas::volume::detail

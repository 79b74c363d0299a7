#include "light_grid.h"
#include "atlas/core/parallel.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace atlas::render::detail {

double exit_distance(const Box3d& b, const Vec3d& p, const Vec3d& d) {
    double t1 = std::numeric_limits<double>::infinity();
    for (int a = 0; a < 3; ++a) {
        if (d[a] > 1e-12) t1 = std::min(t1, (b.max[a] - p[a]) / d[a]);
        else if (d[a] < -1e-12) t1 = std::min(t1, (b.min[a] - p[a]) / d[a]);
    }
    return std::isfinite(t1) ? std::max(0.0, t1) : 0.0;
}

LightGrid::LightGrid(const CloudSampler& cloud, Vec3i res, Vec3d sun_dir)
    : LightGrid(cloud.bounds(), res, sun_dir, [&cloud](double x, double y, double z) { return cloud.density_at(x, y, z, 1e30); }) {}

LightGrid::LightGrid(const Box3d& bounds, Vec3i res, Vec3d sun_dir, const DensityFn& density) : res_(res), bounds_(bounds), sun_dir_(sun_dir) {
    for (int a = 0; a < 3; ++a) voxel_[a] = bounds_.size()[a] / res_[a];
    const size_t n = size_t(res_[0]) * size_t(res_[1]) * size_t(res_[2]);
    const size_t row = size_t(res_[0]), slab = row * size_t(res_[1]);
    // 1. The density at the grid's voxel centres (voxels: no near-camera detail).
    dens_.assign(n, 0.0f);
    std::vector<float>& dens = dens_;
    parallel_for_index(res_[2], [&](int z) {
        for (int y = 0; y < res_[1]; ++y)
            for (int x = 0; x < res_[0]; ++x) {
                const double px = bounds_.min[0] + (x + 0.5) * voxel_[0];
                const double py = bounds_.min[1] + (y + 0.5) * voxel_[1];
                const double pz = bounds_.min[2] + (z + 0.5) * voxel_[2];
                dens[size_t(z) * slab + size_t(y) * row + size_t(x)] = density(px, py, pz);
            }
    });
    // 2. Toward the sky: a running sum down each column (midpoint rule).
    sky_.assign(n, 0.0f);
    parallel_for_index(res_[1], [&](int y) {
        for (int x = 0; x < res_[0]; ++x) {
            double acc = 0;
            for (int z = res_[2] - 1; z >= 0; --z) {
                const size_t i = size_t(z) * slab + size_t(y) * row + size_t(x);
                sky_[i] = static_cast<float>(acc + 0.5 * dens[i] * voxel_[2]);
                acc += dens[i] * voxel_[2];
            }
        }
    });
    // 3. Toward the sun: march the coarse density from each voxel centre.
    //    A sample whose trilinear cell has eight zero corners adds exactly 0,
    //    so it is skipped after a one-byte test (most of a sparse cloud's
    //    grid is empty; same bytes as sampling it).
    std::vector<unsigned char> occupied(n, 0);
    parallel_for_index(res_[2], [&](int z) {
        const int z1 = std::min(z + 1, res_[2] - 1);
        for (int y = 0; y < res_[1]; ++y) {
            const int y1 = std::min(y + 1, res_[1] - 1);
            for (int x = 0; x < res_[0]; ++x) {
                const int x1 = std::min(x + 1, res_[0] - 1);
                bool any = false;
                for (int zz : {z, z1})
                    for (int yy : {y, y1})
                        for (int xx : {x, x1}) any = any || dens[size_t(zz) * slab + size_t(yy) * row + size_t(xx)] != 0.0f;
                occupied[size_t(z) * slab + size_t(y) * row + size_t(x)] = any ? 1 : 0;
            }
        }
    });
    // The occupied cells' index box: along a ray each cell index moves one
    // way, so once one leaves the box toward the sun, nothing follows.
    int lo[3] = {res_[0], res_[1], res_[2]}, hi[3] = {-1, -1, -1};
    for (int z = 0; z < res_[2]; ++z)
        for (int y = 0; y < res_[1]; ++y)
            for (int x = 0; x < res_[0]; ++x)
                if (occupied[size_t(z) * slab + size_t(y) * row + size_t(x)]) {
                    const int c[3] = {x, y, z};
                    for (int a = 0; a < 3; ++a) {
                        lo[a] = std::min(lo[a], c[a]);
                        hi[a] = std::max(hi[a], c[a]);
                    }
                }
    // 1 = the sample's cell is occupied, 0 = not, -1 = neither is any later one.
    auto cell_occupied = [&](const Vec3d& q) {
        size_t i = 0;
        const size_t stride[3] = {1, row, slab};
        for (int a = 0; a < 3; ++a) {
            const double v = std::clamp((q[a] - bounds_.min[a]) / voxel_[a] - 0.5, 0.0, double(res_[a] - 1));
            const int k = std::min(static_cast<int>(v), res_[a] - 1);
            if ((sun_dir[a] > 0 && k > hi[a]) || (sun_dir[a] < 0 && k < lo[a])) return -1;
            i += size_t(k) * stride[a];
        }
        return occupied[i] != 0 ? 1 : 0;
    };
    sun_.assign(n, 0.0f);
    const double step = 0.75 * std::min({voxel_[0], voxel_[1], voxel_[2]});
    parallel_for_index(res_[2], [&](int z) {
        for (int y = 0; y < res_[1]; ++y)
            for (int x = 0; x < res_[0]; ++x) {
                const Vec3d p{{bounds_.min[0] + (x + 0.5) * voxel_[0], bounds_.min[1] + (y + 0.5) * voxel_[1],
                               bounds_.min[2] + (z + 0.5) * voxel_[2]}};
                const double len = exit_distance(bounds_, p, sun_dir);
                const int steps = static_cast<int>(std::ceil(len / step));
                double acc = 0;
                for (int s = 0; s < steps; ++s) {
                    const double t0 = s * step, dt = std::min(step, len - t0);
                    const Vec3d q = p + sun_dir * (t0 + 0.5 * dt);
                    const int o = cell_occupied(q);
                    if (o < 0) break;
                    if (o) acc += sample(dens, q[0], q[1], q[2]) * dt;
                }
                sun_[size_t(z) * slab + size_t(y) * row + size_t(x)] = static_cast<float>(acc);
            }
    });
}

float LightGrid::sample(const std::vector<float>& g, double x, double y, double z) const {
    double u[3] = {(x - bounds_.min[0]) / voxel_[0] - 0.5, (y - bounds_.min[1]) / voxel_[1] - 0.5, (z - bounds_.min[2]) / voxel_[2] - 0.5};
    int i0[3], i1[3];
    float t[3];
    for (int a = 0; a < 3; ++a) {
        double v = std::clamp(u[a], 0.0, double(res_[a] - 1));
        i0[a] = std::min(static_cast<int>(v), res_[a] - 1);
        i1[a] = std::min(i0[a] + 1, res_[a] - 1);
        t[a] = static_cast<float>(v - i0[a]);
    }
    const size_t row = size_t(res_[0]), slab = row * size_t(res_[1]);
    auto at = [&](int xx, int yy, int zz) { return g[size_t(zz) * slab + size_t(yy) * row + size_t(xx)]; };
    float c00 = at(i0[0], i0[1], i0[2]) + (at(i1[0], i0[1], i0[2]) - at(i0[0], i0[1], i0[2])) * t[0];
    float c10 = at(i0[0], i1[1], i0[2]) + (at(i1[0], i1[1], i0[2]) - at(i0[0], i1[1], i0[2])) * t[0];
    float c01 = at(i0[0], i0[1], i1[2]) + (at(i1[0], i0[1], i1[2]) - at(i0[0], i0[1], i1[2])) * t[0];
    float c11 = at(i0[0], i1[1], i1[2]) + (at(i1[0], i1[1], i1[2]) - at(i0[0], i1[1], i1[2])) * t[0];
    float c0 = c00 + (c10 - c00) * t[1], c1 = c01 + (c11 - c01) * t[1];
    return c0 + (c1 - c0) * t[2];
}

} // namespace atlas::render::detail

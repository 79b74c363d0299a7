// Internal: the precomputed voxel light grid (Nubis³): for every voxel, the
// density integrated (density x metres) along the ray toward the sun and
// straight up toward the sky, to the volume boundary.
#pragma once

#include "cloud_sampler.h"

#include <vector>

namespace atlas::render::detail {

class LightGrid {
public:
    // Builds both grids at `res` over the cloud's bounds (TBB, deterministic).
    LightGrid(const CloudSampler& cloud, Vec3i res, Vec3d sun_dir);
    // Summed density toward the sun / the sky from world point p (trilinear).
    float sun(double x, double y, double z) const { return sample(sun_, x, y, z); }
    float sky(double x, double y, double z) const { return sample(sky_, x, y, z); }
    double voxel_min() const { return std::min({voxel_[0], voxel_[1], voxel_[2]}); }

private:
    float sample(const std::vector<float>& g, double x, double y, double z) const;
    Vec3i res_;
    Box3d bounds_;
    Vec3d voxel_;
    std::vector<float> sun_, sky_;
};

// Length of the ray p + t*d (t >= 0) inside box b (0 when it misses).
double exit_distance(const Box3d& b, const Vec3d& p, const Vec3d& d);

} // namespace atlas::render::detail

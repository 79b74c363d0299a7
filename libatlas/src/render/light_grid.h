// Internal: the precomputed voxel light grid (Nubis³): for every voxel, the
// density integrated (density x metres) along the ray toward the sun and
// straight up toward the sky, to the volume boundary.
#pragma once

#include "cloud_sampler.h"

#include <functional>
#include <vector>

namespace atlas::render::detail {

class LightGrid {
public:
    // Density (at density 1 = extinction per metre) at a grid point.
    using DensityFn = std::function<float(double x, double y, double z)>;
    // Builds both grids at `res` over the cloud's bounds (TBB, deterministic).
    LightGrid(const CloudSampler& cloud, Vec3i res, Vec3d sun_dir);
    // The same over any box and density: the 2.5D layer's flattened shell
    // (x, y, altitude). `density` is called from several threads.
    LightGrid(const Box3d& bounds, Vec3i res, Vec3d sun_dir, const DensityFn& density);
    // Summed density toward the sun / the sky from world point p (trilinear).
    float sun(double x, double y, double z) const { return sample(sun_, x, y, z); }
    float sky(double x, double y, double z) const { return sample(sky_, x, y, z); }
    double voxel_min() const { return std::min({voxel_[0], voxel_[1], voxel_[2]}); }
    // The grid itself (x fastest): density at the voxel centres and the
    // summed density toward the sun from them (the diffusion term's input).
    Vec3i resolution() const { return res_; }
    const Vec3d& voxel() const { return voxel_; }
    const Box3d& bounds() const { return bounds_; }
    const std::vector<float>& density() const { return dens_; }
    const std::vector<float>& sun_depths() const { return sun_; }
    const Vec3d& sun_direction() const { return sun_dir_; }

private:
    float sample(const std::vector<float>& g, double x, double y, double z) const;
    Vec3i res_;
    Box3d bounds_;
    Vec3d voxel_;
    Vec3d sun_dir_;
    std::vector<float> dens_, sun_, sky_;
};

// Length of the ray p + t*d (t >= 0) inside box b (0 when it misses).
double exit_distance(const Box3d& b, const Vec3d& p, const Vec3d& d);

} // namespace atlas::render::detail

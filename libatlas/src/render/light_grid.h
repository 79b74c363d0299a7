// Internal: the precomputed voxel light grid (Nubis³): for every voxel, the
// density integrated (density x metres) along the ray toward the sun, to the
// volume boundary - the diffusion term's source. The voxel march reads the sun
// and the sky from SunDepthMap below.
#pragma once

#include "cloud_sampler.h"

#include <functional>
#include <vector>

namespace atlas::render::detail {

class LightGrid {
public:
    // Density (at density 1 = extinction per metre) at a grid point.
    using DensityFn = std::function<float(double x, double y, double z)>;
    // Builds the grid at `res` over the cloud's bounds (TBB, deterministic).
    LightGrid(const CloudSampler& cloud, Vec3i res, Vec3d sun_dir);
    // The same over any box and density: the 2.5D layer's flattened shell
    // (x, y, altitude). `density` is called from several threads.
    LightGrid(const Box3d& bounds, Vec3i res, Vec3d sun_dir, const DensityFn& density);
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
    std::vector<float> dens_, sun_;
};

// The summed density toward the sun, exact along the ray and at the
// volume's own resolution across it. A grid cell's trilinear blend mixes
// depths of rays that pass either side of a lobe, so a 36 m light grid over
// 16 m lobes darkened sunlit surfaces (18% against Cycles) and blurred
// shadow edges (99.9th percentile 17-23/255 against marched light). Here the
// table is sheared so that each of its columns is one ray toward the sun:
// the axis the sun leans along most is the march axis `a`, and a point p
// maps to (p_a, p_b - s_b (p_a - a0), p_c - s_c (p_a - a0)) with
// s = sun / sun_a, constant along the ray. A column is a running sum of
// density samples (cost: one sample per cell, not one march per cell), and
// only the interpolation across columns blurs, by at most a voxel.
class SunDepthMap {
public:
    // `voxel`: the sample spacing per world axis (the volume's voxels);
    // across the rays it is divided by `across`.
    // `distance` (optional): the SDF, a ball of that radius about a point holding no
    // cloud; the samples of a column inside it are 0 without a density lookup (as the
    // view march's sphere tracing crosses them).
    SunDepthMap(const Box3d& bounds, Vec3d voxel, Vec3d sun_dir, const LightGrid::DensityFn& density, double across = 1.0,
                const LightGrid::DensityFn* distance = nullptr);
    // Summed density from p to the bounds toward the sun (trilinear).
    float sun(double x, double y, double z) const;
    // The smallest sample spacing (the march's near samples are half of it).
    double voxel_min() const { return std::min({voxel_[0], voxel_[1], voxel_[2]}); }
    size_t cells() const { return depth_.size(); }
    size_t columns() const { return cols_.size(); }

private:
    struct Column {
        int first = 0, count = 0; // the samples inside the bounds, along a
        size_t offset = 0;        // into depth_
        float total = 0;          // the whole column's summed density
    };
    float at(int i, int j, int k) const;
    int a_ = 2, b_ = 0, c_ = 1; // march axis and the two across it
    double sb_ = 0, sc_ = 0;    // shear: sun_b / sun_a, sun_c / sun_a
    double a0_ = 0;             // bounds.min[a]
    double u0_ = 0, v0_ = 0;    // the sheared table's lower corner across the rays
    int n_[3] = {1, 1, 1};      // samples along a, columns along u (b) and v (c)
    bool toward_plus_ = true;   // the sun lies toward +a
    Vec3d voxel_;
    std::vector<Column> cols_;  // index k * n_[1] + j
    std::vector<float> depth_;
};

// Length of the ray p + t*d (t >= 0) inside box b (0 when it misses).
double exit_distance(const Box3d& b, const Vec3d& p, const Vec3d& d);

} // namespace atlas::render::detail

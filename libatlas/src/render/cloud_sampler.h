// Internal: density of the voxel cloud at a world position (the Nubis³
// up-rez), shared by the view march, the light grid and reference mode.
#pragma once

#include "atlas/render/scene.h"

#include <array>
#include <cmath>

namespace atlas::render::detail {

struct Grid4 {
    // dimensional profile, detail type, density scale, sdf
    std::array<const float*, 4> ch{};
    // A channel whose voxels all hold one finite value (a plain density
    // grid's detail type 0 and density scale S) is not interpolated: its
    // trilinear blend is that value exactly.
    std::array<bool, 4> uniform{};
    std::array<float, 4> value{};
    int nx = 0, ny = 0, nz = 0;
    double min[3]{}, inv_voxel[3]{};
};

struct NoiseGrid {
    std::array<const float*, 4> ch{};
    int nx = 0, ny = 0, nz = 0;
    double scale[3]{}; // world metres -> noise voxels
};

struct VoxelSample {
    float profile = 0, type = 0, scale = 0, sdf = 0;
};

class CloudSampler {
public:
    // Throws via validate_scene.
    explicit CloudSampler(const CloudScene& scene);

    // Trilinear sample of the four channels. Outside the cloud (sdf >= 0 or
    // NaN) only the sdf is looked up and the other fields are 0: no caller
    // reads them there (density() returns 0, the march skips the sample).
    VoxelSample voxel(double x, double y, double z) const;
    // The sdf alone (the march's empty-space test): voxel(x, y, z).sdf.
    float sdf(double x, double y, double z) const;
    // Up-rezzed density (>= 0, finite) from a voxel sample; camera_distance
    // drives the near-camera twice-folded noise (pass a large value to skip).
    float density(const VoxelSample& v, double x, double y, double z, double camera_distance) const;
    // Both steps at once; 0 outside the cloud (SDF >= 0).
    float density_at(double x, double y, double z, double camera_distance) const {
        VoxelSample v = voxel(x, y, z);
        return v.sdf < 0 ? density(v, x, y, z, camera_distance) : 0.0f;
    }

    bool has_noise() const { return noise_.ch[0] != nullptr; }
    bool billowy() const { return billowy_; }
    const Box3d& bounds() const { return bounds_; }
    Vec3d voxel_size() const { return voxel_; }

private:
    struct Cell {
        size_t i000, dx, dy, dz;
        float tx, ty, tz;
        int x0, x1, y0, y1, z0, z1; // the taps' voxels (a block SDF's lookups)
    };
    Cell cell(double x, double y, double z) const;
    float channel(int c, const Cell& k) const;
    float sdf_of(const Cell& k) const; // channel 3, from its blocks when the scene's sdf_block > 1
    std::array<float, 4> noise(double x, double y, double z) const;
    Grid4 grid_;
    NoiseGrid noise_;
    Box3d bounds_;
    Vec3d voxel_;
    bool billowy_ = false;
    int sdf_shift_ = 0, sdf_nx_ = 0, sdf_ny_ = 0; // log2 CloudScene::sdf_block and the block grid
};

// NaN maps to 0 so that bad voxels read as empty rather than poisoning a ray.
inline double saturate(double v) { return v > 0 ? (v < 1 ? v : 1) : 0; }

} // namespace atlas::render::detail

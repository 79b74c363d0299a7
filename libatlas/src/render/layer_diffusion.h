// Internal to the render module: the 2.5D physical mode's diffusion term
// over a patch of the cloud shell (layer.cpp builds it, the march reads it;
// docs/render.md, "Multiple scattering by diffusion").
#pragma once

#include "diffusion.h"
#include "layer_model.h"

#include <array>
#include <memory>

namespace atlas::render::layer_detail {

// Physical mode: the voxel mode's diffusion term (diffusion.h) over a
// flattened patch of the shell, grid coordinates (x, y, altitude), the map's
// x, y projected radially onto the ground sphere. Over 16 km the shell's
// curvature tilts the local up by at most 0.07 degrees from the patch
// centre's, so the sun keeps its world direction in the patch.
class LayerDiffusion {
public:
    static constexpr double kMaxPatchVoxels = 32e6;
    // columns: the grid's voxels across the patch (x, y); vertically from s.light_grid.
    LayerDiffusion(const LayerModel& m, const RenderSettings& s, const Box2d& patch, const std::array<int, 2>& columns, double earth_radius);
    // The P1 in-scattered weights at world p (altitude h) toward the eye:
    // the sun's and the sky basis's (DiffusionGrid::radiances); -1, -1
    // outside the patch (the octaves and the sphere's mean sky alone there).
    // mean_t: DiffusionGrid::mean_sun_transmittance there (-1 outside the
    // patch or the medium).
    void radiances(const Vec3d& p, double h, const Vec3d& toward_eye, double& sun_w, double& sky_w, double& mean_t) const {
        sun_w = sky_w = mean_t = -1;
        const Vec3d c = m_.centre();
        const double up = p[2] - c[2];
        if (!(up > 0)) return;
        // Inverse of the radial projection: the patch point under p.
        const double x = c[0] + radius_ * (p[0] - c[0]) / up, y = c[1] + radius_ * (p[1] - c[1]) / up;
        if (x < box_.min[0] || x > box_.max[0] || y < box_.min[1] || y > box_.max[1] || h < box_.min[2] || h > box_.max[2]) return;
        diffusion_->radiances(x, y, h, toward_eye, sun_w, sky_w, &mean_t);
    }

private:
    const LayerModel& m_;
    double radius_;
    Box3d box_;
    std::unique_ptr<detail::DiffusionGrid> diffusion_;
};

// Where the diffusion patch is centred: under the look-at point when it lies
// in the shell (orbit views, and the patch --export-scene bakes), else where
// the view ray first meets the shell's middle (a ground view sees the
// clouds ahead), else under the camera.
Vec2d diffusion_patch_centre(const LayerModel& m, const Camera& cam, double earth_radius);

} // namespace atlas::render::layer_detail

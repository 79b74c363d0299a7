// Internal: multiple scattering in optically thick media by the diffusion
// approximation, solved on the voxel light grid (docs/render.md, "Multiple
// scattering by diffusion").
//
// Per light-grid voxel: the fluence phi of the light scattered at least once,
// in units of the sun's irradiance E, from
//     -div(D grad phi) + sigma_a phi = Q,   D = 1 / (3 sigma_t (1 - g)),
// Q = sigma_s x (the sun's transmittance averaged over the voxel's mean chord
// along the sun), albedo 1 (sigma_a = 0, sigma_s = sigma_t). Voxels whose
// optical thickness is below kDiffusionMinTau are outside the medium; every
// face between the medium and outside (or the grid's boundary) carries the
// Marshak / extrapolated-boundary condition (phi = 0 a distance 2D beyond the
// face: a face flux phi_i / (3 sigma' h / 2 + 2)), scaled by |n|_2 / |n|_1
// with n the density gradient (a sloped surface drawn in voxel faces has
// |n|_1 times its area). Finite volumes (7-point),
// solved by red-black successive over-relaxation, cascaded from coarse grids
// (2x2x2 averages of density and source) to the light grid with a fixed
// sweep count per level: each colour's update reads only the other colour,
// so the result is the same for any thread count.
//
// The in-scattered radiance of the multiply scattered light at a sample, in
// P1 (radiance phi / 4 pi + 3 F . w / 4 pi, F = -D grad phi the diffuse flux),
// is sigma_s E (phi + 3 g F . w) / (4 pi) toward the eye w; in the renderer's
// units (the sun colour is E / 4 pi, the phase isotropic = 1) that is a sun
// weight of phi + 3 g F . w.
#pragma once

#include "light_grid.h"

#include <vector>

namespace atlas::render::detail {

// A voxel takes part when sigma_t x its smallest edge is at least this.
inline constexpr double kDiffusionMinTau = 1e-3;

class DiffusionGrid {
public:
    // extinction: per metre at density 1; g: the phase function's mean
    // cosine; sweeps: red-black SOR sweeps per level (the coarsest gets 4x).
    DiffusionGrid(const LightGrid& grid, double extinction, double g, int sweeps);
    // phi / E at world point p (trilinear, >= 0; outside-medium voxels next
    // to the medium hold the extrapolation through the Marshak surface value,
    // others 0).
    float fluence(double x, double y, double z) const;
    // The in-scattered radiance weight of the diffuse light toward the eye
    // (unit toward_eye = -view direction) in P1: phi + 3 g F . toward_eye,
    // F = -D grad phi the diffuse flux (per E), clamped at 0; trilinear.
    double radiance(double x, double y, double z, const Vec3d& toward_eye) const;
    // Total source and total outflow through the medium's faces, both per
    // E (square metres): equal when the solve has converged (no absorption).
    double total_source() const { return source_total_; }
    double total_outflow() const { return outflow_total_; }

private:
    Vec3i res_;
    Box3d bounds_;
    Vec3d voxel_;
    void corners(double x, double y, double z, size_t idx[8], double w[8]) const;
    std::vector<float> phi_, flux_; // flux_: 3 per voxel
    double g_ = 0;
    double source_total_ = 0, outflow_total_ = 0;
};

} // namespace atlas::render::detail

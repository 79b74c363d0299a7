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

#include <algorithm>
#include <cstdint>
#include <vector>

namespace atlas::render::detail {

// A voxel takes part when sigma_t x its smallest edge is at least this.
inline constexpr double kDiffusionMinTau = 1e-3;

// The diffuse sun light's sub-voxel share (docs/render.md, "Below the light
// grid"; the 2.5D march, whose sun transmittance is marched per sample): the
// grid's phi comes from the sun's transmittance averaged over a light voxel,
// but the light scattered a few times near a point follows the sun's
// transmittance T there (Cycles' multiply scattered light has the single
// scattering's pixel-scale pattern, which the grid smooths away). The march
// scales the diffuse sun weight by 1 + share (min(cap, T / Tbar) - 1), Tbar the
// voxel mean. Fitted against the four-render Cycles references of the 2.5D
// scenes: share 0.1-0.25 within 0.1 point of each other on the superstorm,
// 0.4 worse than none; an additive form, phi + k (T - Tbar), worse at every k.
// The cap: on a flat deck T / Tbar is the vertical profile the grid's surface
// values already hold; 1.5 keeps the thick deck within 4% of its values
// without the term (cap 2: +6% with the sun high; 1: darkening only, worse).
inline constexpr double kSubgridSunShare = 0.15;
inline constexpr double kSubgridSunCap = 1.5;
inline double subgrid_sun_factor(double t, double tbar) { return 1 + kSubgridSunShare * (std::min(kSubgridSunCap, t / tbar) - 1); }

// Where the medium's surface lies inside the voxels, across the faces turned
// from the sun (docs/render.md, "The patch's edge"): 6 bytes per voxel (face
// (a, side) at 2 a + (side > 0)), the distance from a medium voxel's node to
// the surface in 1/kSurfaceUnits of a voxel on that axis, for each face whose
// neighbour is outside the medium and whose outward normal points away from
// the sun: the depth that holds the same optical thickness at the node's
// density, from kSurfaceSamples densities between the node and the
// neighbour's centre, each min(1, density / the node's) (a sharp edge, every
// sample in or out, located by kSurfaceBisections bisections to 1/64 voxel),
// at least half a sample; half a voxel (the face itself) everywhere else.
// Faces toward the sun keep the face: their source (the sun's transmittance
// over the whole voxel, the near-face deposit) is the full voxel's.
// `density` is the light grid's (called from several threads).
inline constexpr int kSurfaceSamples = 4;
inline constexpr int kSurfaceBisections = 4;
inline constexpr int kSurfaceUnits = 128;
std::vector<uint8_t> shadowed_face_surfaces(const LightGrid& grid, double extinction, const LightGrid::DensityFn& density);

class DiffusionGrid {
public:
    // How voxels several mean free paths thick are treated (the 2.5D
    // patch's, optical depth ~1-5 per voxel; the voxel mode's are ~1, where
    // the first is kept as calibrated):
    //   Thin   the sun's source averaged over the voxel's mean chord along
    //          the sun (volume / projected area); outside voxels next to the
    //          medium hold the Marshak surface value.
    //   Thick  the source is sigma x the mean of T over the whole voxel,
    //          T_c prod_a sinh(x_a) / x_a with x_a half the optical depth's
    //          change across the voxel on axis a (the steeper one-sided
    //          difference, their sum capped at the centre's depth); outside
    //          voxels hold the value extrapolated through the surface value
    //          (2 phi_s - phi), so lookups fall to phi_s at the surface.
    //          Where half a voxel is more than one optical depth thick (fading
    //          in up to 2), the source lies near the sunward face: that
    //          Marshak face passes q h L(x) straight out (L the Langevin
    //          function of half the sun's optical depth change x across the
    //          voxel), and the lookups put the share of the rise to the
    //          node's phi that a view ray meets within the source's depth at
    //          the face. On a flat deck (tests/render/diffusion_test.cpp) the
    //          mean chord's deposit depends on the sun's angle in thick
    //          voxels (optical depth 5.3 per voxel: 0.43 of Chandrasekhar's
    //          reflection with the sun 25 degrees high, 0.98 at 60); this
    //          stays within 6% at 1.3 per voxel for the sun 25-80 degrees
    //          high, and within 14% at 5.3 per voxel (0.86 / 1.00 / 0.98 with
    //          the sun 25 / 60 / 80 degrees high; 1.35 / 1.36 / 1.30 with
    //          the source at the voxel's centre).
    enum class Voxels { Thin, Thick };
    // extinction: per metre at density 1; g: the phase function's mean
    // cosine; sweeps: red-black SOR sweeps per level (the coarsest gets 4x).
    // forward: the first-scattered light keeps the phase function's forward
    // peak (P1 with an anisotropic source, Q1 = g sigma_s T (-sun)): the
    // flux gains 3 D Q1 = g / (1 - g) T (-sun) and its divergence moves into
    // the source. false: the source is isotropic.
    // sky: also solve the sky's field (radiances' sky). inter_cloud: add the
    // light the medium sheds onto other parts of itself (traced through the
    // grid, two bounces between clouds, the sun's field solved again after
    // each). surfaces (Thick only; shadowed_face_surfaces' layout): a Marshak
    // face whose surface lies d from the node has the resistance 3 sigma' d
    // (1.5 sigma' h at the face), and the outside voxel beyond it holds the
    // value extrapolated linearly through the surface value at d, so that
    // the leak and the lookups follow the surface inside the voxel rather
    // than the lattice (empty: every face at the face).
    DiffusionGrid(const LightGrid& grid, double extinction, double g, int sweeps, Voxels voxels = Voxels::Thin, bool forward = false,
                  bool sky = false, bool inter_cloud = false, std::vector<uint8_t> surfaces = {});
    // Both fields at world point (x, y, z) toward the eye (unit toward_eye =
    // -view direction), trilinear from one set of corner weights (every
    // sample of the march asks for both):
    //   sun  the in-scattered radiance weight of the diffuse sun light in
    //        P1: phi + 3 g F . toward_eye, F = -D grad phi the diffuse flux
    //        (per E), clamped at 0 (outside-medium voxels next to the medium
    //        hold the Marshak surface value or the extrapolation through it
    //        (Voxels), others 0).
    //   sky  the sky's light in the medium (built with sky = true; else -1):
    //        the same P1 weight for the sky basis L(w) = saturate(w . up)
    //        (up = +z) coming in through the medium's faces, divided by
    //        4 pi, so that the sky lerp(horizon, zenith, saturate(w . up))
    //        gives the in-scattered radiance horizon + (zenith - horizon) x
    //        this, every order of scattering included (a uniform sky gives
    //        its own colour: the furnace). 1/4 (the sphere's mean) in an
    //        optically thin medium, up to 2/3 at a thick cloud's top (it
    //        reflects the sky it sees) and 0 at its base (it sees the
    //        horizon colour below).
    //   mean_t  (when given) mean_sun_transmittance at the point, from the
    //        same corner weights.
    void radiances(double x, double y, double z, const Vec3d& toward_eye, double& sun, double& sky, double* mean_t = nullptr) const;
    // The sun's transmittance averaged over the light-grid voxels (the mean the
    // sun's source is formed from), trilinear over the corners inside the medium;
    // -1 where none is.
    double mean_sun_transmittance(double x, double y, double z) const;
    // Total source and total outflow through the medium's faces, both per
    // E (square metres): equal when the solve has converged (no absorption)
    // without inter_cloud (with it the faces also pass on the shed light).
    double total_source() const { return source_total_; }
    double total_outflow() const { return outflow_total_; }

private:
    Vec3i res_;
    Box3d bounds_;
    Vec3d voxel_;
    void corners(double x, double y, double z, size_t idx[8], double w[8]) const;
    double p1_weight(const std::vector<float>& phi, const std::vector<float>& flux, const size_t idx[8], const double w[8], const Vec3d& toward_eye) const;
    double mean_transmittance(const size_t idx[8], const double w[8]) const;
    std::vector<float> phi_, flux_; // flux_: 3 per voxel
    std::vector<float> tbar_; // the fine level's mean sun transmittance per voxel (0 outside the medium)
    std::vector<float> sky_phi_, sky_flux_; // the sky basis's (empty unless built)
    double g_ = 0;
    double source_total_ = 0, outflow_total_ = 0;
};

} // namespace atlas::render::detail

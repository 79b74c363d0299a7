// The 2.5D diffusion patch (layer_diffusion.h).
#include "layer_diffusion.h"

#include "light_grid.h"
#include "atlas/core/parallel.h"

#include <cmath>
#include <cstdio>

namespace atlas::render::layer_detail {

LayerDiffusion::LayerDiffusion(const LayerModel& m, const RenderSettings& s, const Box2d& patch, const std::array<int, 2>& columns, double earth_radius)
        : m_(m), radius_(earth_radius) {
    // `columns` voxels across the patch; vertically at least as many as
    // make the voxels no taller than they are wide (a 13 km storm in 32
    // levels of 400 m: cloud error 36%, bias -7% against Cycles; in 104
    // levels 30%, -2%), plus one empty level above the shell's top and
    // one below its bottom, where the solver keeps the extrapolated
    // surface value (DiffusionGrid::Voxels::Thick).
    const double thickness = m.top() - m.bottom();
    const double dx = std::min((patch.max[0] - patch.min[0]) / columns[0], (patch.max[1] - patch.min[1]) / columns[1]);
    const int levels = std::max(s.light_grid[2] - 2, static_cast<int>(std::ceil(thickness / dx)));
    const double dz = thickness / levels;
    const Vec3i res{{columns[0], columns[1], levels + 2}};
    // Refused before allocating: about 110 bytes per voxel (the light
    // grid's density, sun and sky depths, the solver's levels, the
    // near-face source's depth changes, the shadowed faces' surfaces,
    // the sun's and the sky's fields and fluxes, the shed light's passes).
    const double voxels = double(res[0]) * res[1] * res[2];
    if (voxels > kMaxPatchVoxels) {
        char buf[320];
        std::snprintf(buf, sizeof buf,
                      "render (2.5D): the diffusion patch would hold %d x %d x %d voxels (%.0f M, about %.1f GB; at most %.0f M): lower the light "
                      "grid (--light-grid), or turn the term off (--ms-diffusion off)",
                      res[0], res[1], res[2], voxels / 1e6, voxels * 110 / 1e9, kMaxPatchVoxels / 1e6);
        throw Error(buf);
    }
    box_ = Box3d{{{patch.min[0], patch.min[1], m.bottom() - dz}}, {{patch.max[0], patch.max[1], m.top() + dz}}};
    const Vec3d c = m.centre();
    const Vec3d sun = detail::normalized(s.sun_direction);
    // The light grid is only the solver's input: freed once it has run.
    with_thread_limit(s.threads, [&] {
        const detail::LightGrid::DensityFn density = [&](double x, double y, double a) {
            const Vec3d p = c + detail::normalized(Vec3d{{x - c[0], y - c[1], radius_}}) * (radius_ + a);
            return static_cast<float>(m.density(p, a, true));
        };
        const detail::LightGrid grid(box_, res, sun, density);
        // The shadowed faces' surfaces inside their voxels: without them the
        // superstorm's cut wall took its leak from where the lattice fell
        // (cloud error 9.7 / 11.1 / 10.3 / 10.1% against Cycles with the
        // lattice shifted by 0 / 1/4 / 1/2 / 3/4 voxel; with them 9.3-9.8%).
        std::vector<uint8_t> surfaces = detail::shadowed_face_surfaces(grid, s.extinction, density);
        diffusion_ = std::make_unique<detail::DiffusionGrid>(grid, s.extinction, detail::phase_mean_cosine(s), s.ms_diffusion_sweeps,
                                                             detail::DiffusionGrid::Voxels::Thick, true, true, s.ms_inter_cloud, std::move(surfaces));
    });
}

// Where the diffusion patch is centred: under the look-at point when it lies
// in the shell (orbit views, and the patch --export-scene bakes), else where
// the view ray first meets the shell's middle (a ground view sees the
// clouds ahead), else under the camera.
Vec2d diffusion_patch_centre(const LayerModel& m, const Camera& cam, double earth_radius) {
    const double h = m.altitude(cam.look_at);
    if (h >= m.bottom() && h <= m.top()) return {{cam.look_at[0], cam.look_at[1]}};
    const Vec3d d = detail::normalized(cam.look_at - cam.position);
    const double t = ray_sphere_exit_or_hit(cam.position, d, m.centre(), earth_radius + 0.5 * (m.bottom() + m.top()));
    if (t > 0) {
        const Vec3d p = cam.position + d * t;
        return {{p[0], p[1]}};
    }
    return {{cam.position[0], cam.position[1]}};
}

} // namespace atlas::render::layer_detail

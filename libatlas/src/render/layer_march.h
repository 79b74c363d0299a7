// Internal to the render module: the 2.5D ray march (render_layer runs it
// per pixel): the steps through the cloud shell, the cheap search, cone-
// sampled sun light, the sky light, point lights and what lies behind the
// clouds (docs/render.md, "2.5D mode").
#pragma once

#include "layer_diffusion.h"
#include "layer_model.h"
#include "atlas/render/lights.h"
#include "render_common.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

namespace atlas::render::layer_detail {

// Both roots of |o + t d - c|^2 = r^2 (unit d); false when the ray misses.
inline bool sphere_roots(const Vec3d& o, const Vec3d& d, const Vec3d& c, double r, double& t0, double& t1) {
    const Vec3d oc = o - c;
    const double b = dot(oc, d);
    // c_term computed as (|oc| - r)(|oc| + r): no cancellation for r ~ 6e6 m.
    const double len = length(oc);
    const double cterm = (len - r) * (len + r);
    const double disc = b * b - cterm;
    if (disc < 0) return false;
    const double sq = std::sqrt(disc);
    // Stable quadratic roots.
    const double q = b > 0 ? -(b + sq) : -(b - sq);
    double a0 = q, a1 = q != 0 ? cterm / q : 0;
    if (a0 > a1) std::swap(a0, a1);
    t0 = a0;
    t1 = a1;
    return true;
}

// The march's optical-depth bound per step in cloud, and the shortest step it asks for.
constexpr double kMaxStepTau = 1.0;
constexpr double kMinCappedStep = 2.0; // metres
constexpr int kEntryBisections = 4;
// While most of the view is still ahead (transmittance above kSurfaceLayer) the
// in-cloud step is kSurfaceDetailStep of detail_step (0.8 detail texels): the
// surface layer is what the eye sees, and wisps 50-90 m deep along a ray took
// one 58 m sample at a random depth (grain against 16x the steps: superstorm
// ground 3.09 -> 1.97/255, hzd_weather ground 1.45 -> 0.66; +22-32% render time,
// bench/grain.sh). Deeper samples keep the full detail step. The draft keeps
// its speed: the fraction rises to 1 as the quality falls from 1 to 0.5 (the
// superstorm's proxy edits at quality 0.5 took 0.89-0.91 s with it, 0.78-0.83
// without; docs/PERFORMANCE.md).
constexpr double kSurfaceLayer = 0.7;
constexpr double kSurfaceDetailStep = 0.4;
inline double surface_detail_fraction(double quality) {
    return kSurfaceDetailStep + (1 - kSurfaceDetailStep) * std::clamp((1 - quality) / 0.5, 0.0, 1.0);
}

struct LayerIntegrator {
    const LayerModel& m;
    const LayerScene& sc;
    const RenderSettings& s;
    Vec3d sun;
    Vec3d cam_up; // local up at the camera
    double base_step, grow, max_step;
    double step_quality; // what the steps are divided by: the quality, 4x that in the physical mode
    double light_step;
    double r_ground, r_inner, r_outer;
    bool use_envelope;
    const detail::Sky& sky;
    Vec3f haze_colour;
    Vec3d cone_kernel[6];
    const std::vector<PointLight>& lights; // point lights and flashes (lights.h)
    double light_core2;
    const LayerDiffusion* diffusion; // null unless physical with ms_diffusion
    // In cloud a step is at most 2 detail texels / quality (58 m at the
    // default 1200 m tile of 32 texels): the step that grows with distance
    // (700 m at 35 km) sampled the detail noise's billows at random, a grain
    // of 3-12/255 RMS against 16x the steps (docs/look.md).
    double detail_step = std::numeric_limits<double>::infinity();
    double surface_detail_step = std::numeric_limits<double>::infinity(); // while trans > kSurfaceLayer

    // The ray from p toward the sun meets the ground sphere ahead of p.
    bool earth_hides_sun(const Vec3d& p) const;
    // Summed density (density x metres) toward a point light, the sun (cone
    // samples; marched in the physical mode) and the sky straight up.
    double light_depth(const Vec3d& p, const Vec3d& d, double len) const;
    double sun_depth(const Vec3d& p, bool cheap, bool coarse) const;
    double sun_depth_marched(const Vec3d& p) const;
    double sky_depth(const Vec3d& p, double h, const Column& c) const;
    // The march's step at distance t along a ray entering the shell at t0.
    double step_at(double t, double t0) const;

    // The cheap search's stride: half the step. At twice the step (1.4 km
    // at 35 km) it stepped over the thin edges of lobes and small far clouds
    // at random, a speckle along every silhouette.
    static double search_stride(double step) { return 0.5 * step; }

    // One view ray: its in-scattered radiance and transmittance, the
    // distance behind which the background shows, and its sample counts.
    void trace(const Vec3d& o, const Vec3d& dir, float jitter, double rgb[3], double& trans, double& bg_weight_t, uint64_t& cheap,
               uint64_t& full, uint64_t& skipped) const;

    // What lies behind the clouds along dir: sky (with 2D layers) or ground.
    void background(const Vec3d& o, const Vec3d& dir, double out[3]) const;
};

} // namespace atlas::render::layer_detail

// The 2.5D cloudscape ray-marcher (atlas/render/layer.h; formulas in
// docs/render.md, "2.5D mode").
#include "atlas/render/layer.h"

#include "diffusion.h"
#include "layer_model.h"
#include "light_grid.h"
#include "render_common.h"
#include "atlas/core/parallel.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <memory>

namespace atlas::render {

std::vector<std::string> LayerReport::active_features() const {
    std::vector<std::string> f{"curved_earth", "vertical_profile_lut"};
    if (base_noise) f.push_back("base_noise");
    if (detail_noise) f.push_back("detail_erosion");
    if (curl) f.push_back("curl_distortion");
    if (wind) f.push_back("wind");
    if (precipitation) f.push_back("rain_absorption");
    if (anvil) f.push_back("anvil");
    if (vortex) f.push_back("vortex_rings");
    if (cheap_search) f.push_back("cheap_search");
    if (cone_skipping) f.push_back("cone_skipping");
    if (distance_skipping) f.push_back("distance_skipping");
    if (diffusion) f.push_back("ms_diffusion");
    f.push_back("cone_light_samples");
    f.push_back("beer_powder");
    f.push_back("dual_hg");
    f.push_back("ambient");
    f.push_back("multiple_scattering");
    f.push_back("haze");
    if (sky_gradient) f.push_back("sky_gradient");
    if (sky_layers > 0) f.push_back("sky_layers");
    if (point_lights > 0) f.push_back("point_lights");
    return f;
}

namespace {

// True when some value in [p, p + n) is NaN or Inf (exponent bits all set):
// a branch-free OR the compiler vectorises, so the whole-map scan every
// preview frame makes costs a fraction of isfinite per texel.
bool any_non_finite(const float* p, size_t n) {
    uint32_t bad = 0;
    for (size_t i = 0; i < n; ++i) {
        uint32_t bits;
        std::memcpy(&bits, p + i, sizeof bits);
        bad |= uint32_t((bits & 0x7f800000u) == 0x7f800000u);
    }
    return bad != 0;
}

template <class F>
void check_finite_impl(const F& f, const std::string& what, int nx, int ny) {
    for (int c = 0; c < f.channels(); ++c) {
        auto ch = f.channel(c);
        if (!any_non_finite(ch.data(), ch.size())) continue;
        for (size_t i = 0; i < ch.size(); ++i) {
            if (std::isfinite(ch[i])) continue;
            const size_t plane = size_t(nx) * size_t(ny);
            const size_t x = i % size_t(nx), y = (i / size_t(nx)) % size_t(ny), z = i / plane;
            std::string at = "(" + std::to_string(x) + ", " + std::to_string(y);
            if (plane < ch.size()) at += ", " + std::to_string(z);
            at += ")";
            const std::string name = c < int(f.channel_names().size()) ? f.channel_names()[size_t(c)] : std::to_string(c);
            throw Error(what + ": channel '" + name + "' holds " + (std::isnan(ch[i]) ? "NaN" : "Inf") + " at texel " + at);
        }
    }
}

} // namespace

void check_finite(const Field2D& f, const std::string& what) { check_finite_impl(f, what, f.width(), f.height()); }
void check_finite(const Field3D& f, const std::string& what) { check_finite_impl(f, what, f.nx(), f.ny()); }

// The density model: layer_model.h.
using namespace layer_detail;

namespace {


// Both roots of |o + t d - c|^2 = r^2 (unit d); false when the ray misses.
bool sphere_roots(const Vec3d& o, const Vec3d& d, const Vec3d& c, double r, double& t0, double& t1) {
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

} // namespace

double ray_sphere_exit_or_hit(const Vec3d& o, const Vec3d& d, const Vec3d& centre, double r) {
    double t0, t1;
    if (!sphere_roots(o, d, centre, r, t0, t1)) return -1;
    if (t0 >= 0) return t0;
    if (t1 >= 0) return t1;
    return -1;
}

int shell_segments(const Vec3d& o, const Vec3d& d, const Vec3d& c, double r_ground, double r_inner, double r_outer, double seg[4]) {
    double o0, o1;
    if (!sphere_roots(o, d, c, r_outer, o0, o1) || o1 <= 0) return 0;
    double start = std::max(0.0, o0), end = o1;
    // The ground stops the ray.
    double g0, g1;
    // (A ray tangent to the ground, chord 0, is not blocked.)
    if (sphere_roots(o, d, c, r_ground, g0, g1) && g0 >= 0 && g1 > g0) end = std::min(end, g0);
    double i0, i1;
    int n = 0;
    auto push = [&](double a, double b) {
        if (b > a) {
            seg[2 * n] = a;
            seg[2 * n + 1] = b;
            ++n;
        }
    };
    if (sphere_roots(o, d, c, r_inner, i0, i1) && i1 > start) {
        // Inside the inner sphere between i0 and i1: not in the shell.
        push(start, std::min(end, i0));
        push(std::max(start, i1), end);
    } else {
        push(start, end);
    }
    return n;
}

void validate_layer_scene(const LayerScene& s) {
    need(s.ndf != nullptr, "the NDF set is missing");
    need(s.profile_lut != nullptr, "the vertical-profile LUT is missing");
    for (const char* ch : {"coverage", "min_height", "max_height"})
        need(s.ndf->find_channel(ch) >= 0, std::string("the NDF set has no '") + ch + "' channel");
    for (const char* ch : {"bottom", "top"})
        need(s.profile_lut->find_channel(ch) >= 0, std::string("the profile LUT has no '") + ch + "' channel (ndf/profile_lut)");
    need(s.profile_lut->width() >= 2 && s.profile_lut->height() >= 2, "the profile LUT must be at least 2x2 texels");
    const Box2d& b = s.ndf->bounds();
    need(b.max[0] > b.min[0] && b.max[1] > b.min[1], "the NDF set's bounds are empty");
    check_finite(*s.ndf, "NDF set");
    check_finite(*s.profile_lut, "profile LUT");
    need(!s.base_noise || s.base_noise->channels() >= 1, "base noise has no channels");
    need(!s.detail_noise || s.detail_noise->channels() >= 1, "detail noise has no channels");
    need(!s.curl || s.curl->channels() >= 1, "curl texture has no channels");
    need(positive_finite(s.base_tile), "base_tile must be finite and > 0 metres");
    need(positive_finite(s.detail_tile), "detail_tile must be finite and > 0 metres");
    need(positive_finite(s.curl_tile), "curl_tile must be finite and > 0 metres");
    need(std::isfinite(s.curl_amount) && s.curl_amount >= 0, "curl_amount must be finite and >= 0");
    need(std::isfinite(s.erosion) && s.erosion >= 0 && s.erosion < 1, "erosion must be in [0, 1)");
    need(std::isfinite(s.density_scale) && s.density_scale >= 0, "density_scale must be finite and >= 0");
    need(positive_finite(s.earth_radius), "earth_radius must be finite and > 0 metres");
    need(std::isfinite(s.wind[0]) && std::isfinite(s.wind[1]) && std::hypot(s.wind[0], s.wind[1]) <= 1000, "wind must be finite, at most 1000 m/s");
    need(std::isfinite(s.time), "time must be finite");
    need(std::isfinite(s.cloud_top_offset), "cloud_top_offset must be finite");
    need(std::isfinite(s.rain_absorption) && s.rain_absorption >= 0, "rain_absorption must be finite and >= 0");
    need(std::isfinite(s.haze_distance) && s.haze_distance >= 0, "haze_distance must be finite and >= 0 (0 = none)");
    for (int c = 0; c < 3; ++c) need(std::isfinite(s.ground_albedo[c]) && s.ground_albedo[c] >= 0, "ground_albedo must be finite and >= 0");
    if (s.envelope.cone_map) {
        need(s.envelope.cone_map->find_channel("apex_height") >= 0 && s.envelope.cone_map->find_channel("cone_ratio") >= 0,
             "the cone map needs channels apex_height and cone_ratio (ndf/cone_map with robust: true)");
        check_finite(*s.envelope.cone_map, "cone map");
    }
    if (s.envelope.distance_map) check_finite(*s.envelope.distance_map, "distance map");
    if (s.vortex_table) {
        const Field2D& t = *s.vortex_table;
        for (const char* ch : {"inner", "outer", "speed", "overlap_end"})
            need(t.find_channel(ch) >= 0, std::string("the vortex table has no '") + ch + "' channel (ndf/vortex_rings port table)");
        need(t.height() == 1, "the vortex table must be N x 1 texels");
        check_finite(t, "vortex table");
    }
    if (s.anvil) {
        const Box2d& ab = s.anvil->bounds();
        need(ab.max[0] > ab.min[0] && ab.max[1] > ab.min[1], "the anvil map's bounds are empty");
        check_finite(*s.anvil, "anvil map");
    }
    for (size_t i = 0; i < s.sky_layers.size(); ++i) {
        const SkyLayer& l = s.sky_layers[i];
        const std::string w = "sky_layers[" + std::to_string(i) + "]";
        need(l.texture != nullptr, w + ": texture is missing");
        need(l.channel >= 0 && l.channel < l.texture->channels(), w + ": channel out of range");
        need(positive_finite(l.altitude), w + ": altitude must be finite and > 0 metres");
        need(positive_finite(l.tile), w + ": tile must be finite and > 0 metres");
        need(std::isfinite(l.value_min) && std::isfinite(l.value_max) && l.value_max > l.value_min, w + ": value_max must exceed value_min");
        need(l.opacity >= 0 && l.opacity <= 1, w + ": opacity must be in [0, 1]");
        need(std::isfinite(l.wind[0]) && std::isfinite(l.wind[1]), w + ": wind must be finite");
        check_finite(*l.texture, w);
    }
}

namespace {

// layer_reach without the validation (render has validated the scene).
double reach_of(const LayerScene& scene) {
    const Vec2d tex = scene.ndf->voxel_size();
    return 2 * std::max(tex[0], tex[1]) + std::fabs(scene.curl_amount) + std::fabs(scene.cloud_top_offset);
}

// Physical mode: the voxel mode's diffusion term (diffusion.h) over a
// flattened patch of the shell, grid coordinates (x, y, altitude), the map's
// x, y projected radially onto the ground sphere. Over 16 km the shell's
// curvature tilts the local up by at most 0.07 degrees from the patch
// centre's, so the sun keeps its world direction in the patch.
class LayerDiffusion {
public:
    static constexpr double kMaxPatchVoxels = 32e6;
    // columns: the grid's voxels across the patch (x, y); vertically from s.light_grid.
    LayerDiffusion(const LayerModel& m, const RenderSettings& s, const Box2d& patch, const std::array<int, 2>& columns, double earth_radius)
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
    bool earth_hides_sun(const Vec3d& p) const {
        double g0, g1;
        return sphere_roots(p, sun, m.centre(), r_ground, g0, g1) && g0 >= 0 && g1 > g0;
    }

    // Summed density toward a point light `len` metres away: light_samples cheap samples.
    double light_depth(const Vec3d& p, const Vec3d& d, double len) const {
        const int n = s.light_samples;
        double acc = 0;
        for (int i = 0; i < n; ++i) {
            const Vec3d q = p + d * ((i + 0.5) * len / n);
            acc += m.density(q, m.altitude(q), false);
        }
        return acc * len / n;
    }

    // Summed density toward the sun: six samples in a widening cone, then one
    // long sample at three cone lengths (GPU Pro 7, "Cone-Sampled Lighting").
    // Cheap (view ray optically deep, trans < 0.7, or far): base-only density;
    // coarse (trans < 0.3 or far): also the cone's six steps taken as three of
    // twice the length (the same 6 light steps covered; docs/PERFORMANCE.md
    // "2.5D", error against quality 3).
    // A sun the Earth hides (below p's local horizon) gives an infinite depth, in both modes.
    double sun_depth(const Vec3d& p, bool cheap, bool coarse) const {
        if (earth_hides_sun(p)) return std::numeric_limits<double>::infinity();
        double acc = 0;
        if (coarse) {
            for (int i = 0; i < 3; ++i) {
                const double u = 2.0 * i + 1.0; // the middle of light steps 2i, 2i + 1
                const Vec3d q = p + sun * (u * light_step) + cone_kernel[2 * i] * (light_step * u * 0.5);
                acc += m.density(q, m.altitude(q), false) * 2 * light_step;
            }
            const Vec3d q = p + sun * (18 * light_step);
            return acc + m.density(q, m.altitude(q), false) * 6 * light_step;
        }
        for (int i = 0; i < 6; ++i) {
            const Vec3d q = p + sun * ((i + 0.5) * light_step) + cone_kernel[i] * (light_step * (i + 0.5) * 0.5);
            acc += m.density(q, m.altitude(q), !cheap) * light_step;
        }
        const Vec3d q = p + sun * (18 * light_step);
        acc += m.density(q, m.altitude(q), false) * 6 * light_step;
        return acc;
    }

    // Physical mode: the summed density toward the sun marched with full
    // samples to the shell's top, steps from 1/64 of a light step growing
    // by 1.25 (at most 52, about as far as 40 from a quarter): the cone's
    // sideways spread, its cheap base-only samples and its end at 21 light
    // steps made a far cumulus field's single scattering 41% too dark
    // against Cycles; a first step of a quarter light step (30 m in the
    // superstorm, whose mean free path is ~25 m) missed the sun's first
    // mean free path (superstorm 16.6% -> 13.8% cloud error; docs/render.md,
    // "2.5D against Cycles").
    // A sun the Earth hides (below the local horizon) gives an infinite depth.
    double sun_depth_marched(const Vec3d& p) const {
        if (earth_hides_sun(p)) return std::numeric_limits<double>::infinity();
        const double len = ray_sphere_exit_or_hit(p, sun, m.centre(), r_outer);
        if (!(len > 0)) return 0;
        double acc = 0, t = 0, dt = light_step / 64;
        for (int i = 0; i < 52 && t < len; ++i) {
            const double step = std::min(dt, len - t);
            const Vec3d q = p + sun * (t + 0.5 * step);
            acc += m.density(q, m.altitude(q), true) * step;
            t += step;
            dt *= 1.25;
        }
        return acc;
    }

    // Summed density straight up to the column's top (2 samples of the
    // noise's mean, LayerModel::mean_density: the sky's light comes from the
    // whole hemisphere, not down one line through the billows).
    double sky_depth(const Vec3d& p, double h, const Column& c) const {
        const double len = c.max_h - h;
        if (!(len > 0)) return 0;
        const Vec3d up = detail::normalized(p - m.centre());
        double acc = 0;
        for (int i = 0; i < 2; ++i) {
            const Vec3d q = p + up * ((i + 0.5) * 0.5 * len);
            acc += m.mean_density(q, m.altitude(q));
        }
        return acc * 0.5 * len;
    }

    // The march's step at distance t along a ray entering the shell at t0.
    // Capped at max_step near the camera; beyond 40 km the cap grows with
    // distance (1 %), where haze and size hide the step noise (2 % from 20
    // km left the horizon's far tops half missed: envelope_mountain from
    // above 2.14/255 RMS against 16x the steps, 1.70 at 1 %, for 3 % more
    // time). Physical mode:
    // distance counts from where the ray enters the shell, not from the
    // camera (an orbit camera 50 km out would otherwise step 600 m through
    // kilometre cumulus).
    double step_at(double t, double t0) const {
        const double td = s.artistic ? t : t - t0;
        return std::min(std::max(max_step, 0.01 * td / step_quality), base_step * (1 + td / grow));
    }

    // The cheap search's stride: half the step. At twice the step (1.4 km
    // at 35 km) it stepped over the thin edges of lobes and small far clouds
    // at random, a speckle along every silhouette.
    static double search_stride(double step) { return 0.5 * step; }

    void trace(const Vec3d& o, const Vec3d& dir, float jitter, double rgb[3], double& trans, double& bg_weight_t, uint64_t& cheap,
               uint64_t& full, uint64_t& skipped) const {
        rgb[0] = rgb[1] = rgb[2] = 0;
        trans = 1;
        bg_weight_t = std::numeric_limits<double>::infinity();
        double seg[4];
        const int nseg = shell_segments(o, dir, m.centre(), r_ground, r_inner, r_outer, seg);
        const detail::SunTerms st = detail::sun_terms(s, dot(dir, sun));
        const double ext = s.extinction;
        int steps = 0;
        // A bound on a ray's work that a grazing ray through the layer (over
        // 200 km of shell) at any quality stays under.
        const int max_steps = static_cast<int>(4096 * std::max(1.0, step_quality));
        for (int si = 0; si < nseg && steps < max_steps; ++si) {
            double t = seg[2 * si];
            const double t_end = seg[2 * si + 1];
            bool first = true, searching = true;
            int zero_run = 0;
            // In cloud, a step is at most kMaxStepTau / quality optical depths
            // (set from the last sample's extinction): a 700 m step into a
            // storm whose mean free path is 25 m put each pixel's surface at a
            // random depth, a grain that 16x the samples did not show.
            double tau_cap = std::numeric_limits<double>::infinity();
            // The first full step after the search found cloud ends at most
            // twice as far past the entry as the point the search saw cloud
            // at: a ray crossing a thin edge (a lobe's rim, or the sliver
            // where the map's heights change between two texels) is in the
            // shape for metres, and a 58 m step's midpoint fell beyond it at
            // random (fc6 from the ground 1.64 -> 1.43/255 RMS against 16x the
            // steps, bench/grain.sh).
            double entry_cap = std::numeric_limits<double>::infinity();
            while (t < t_end && steps < max_steps) {
                ++steps;
                double dt = step_at(t, seg[0]);
                if (first) dt *= 0.5 + 0.5 * jitter; // jittered start
                first = false;
                if (searching) {
                    // Cheap search (search_stride); step back on a hit.
                    const Vec3d p = o + dir * t;
                    const double h = m.altitude(p);
                    if (use_envelope) {
                        const double skip = m.skip_distance(p, dir, h);
                        if (skip > search_stride(dt)) {
                            // Walk the search's own strides over the empty stretch
                            // without sampling: every stride whose sample point lies
                            // in it would have found nothing, so the march goes on
                            // exactly where it would have without the envelope (same
                            // picture; jumping straight to the skip's end followed the
                            // smooth envelope and carved terraces into cloud tops).
                            const double end = t + skip;
                            ++skipped;
                            bool ended = false;
                            for (;;) {
                                const double len = std::min(search_stride(dt), t_end - t);
                                if (!(t + 0.5 * len < end)) break; // this stride's sample may see cloud
                                t += len;
                                if (!(t < t_end && steps < max_steps)) {
                                    ended = true; // where the march would have ended
                                    break;
                                }
                                ++steps;
                                dt = step_at(t, seg[0]);
                            }
                            if (ended) break;
                            --steps; // the next pass counts the stride it takes
                            continue;
                        }
                    }
                    const double len = std::min(search_stride(dt), t_end - t);
                    const double hit = t + 0.5 * len;
                    const Vec3d q = o + dir * hit;
                    ++cheap;
                    if (m.density(q, m.altitude(q), false) > 0) {
                        searching = false;
                        zero_run = 0;
                        // Find where the stride entered the cloud (bisection on the
                        // cheap shape, to 1/16 of the half stride): the full march then
                        // starts at the surface instead of up to a stride deep, which
                        // at the far steps put each pixel's surface sample at a random
                        // depth (grain).
                        double a = t, b = hit;
                        for (int k = 0; k < kEntryBisections; ++k) {
                            const double mid = 0.5 * (a + b);
                            const Vec3d r = o + dir * mid;
                            ++cheap;
                            (m.density(r, m.altitude(r), false) > 0 ? b : a) = mid;
                        }
                        entry_cap = std::max(kMinCappedStep, 2 * (hit - a));
                        t = a;
                        continue; // re-march this stretch with full samples
                    }
                    t += len;
                    continue;
                }
                // Optically deep (under 10 % of the view left): what lies further
                // adds at most that much, so it is marched at twice the step.
                dt = std::min({dt, tau_cap, trans > kSurfaceLayer ? surface_detail_step : detail_step, entry_cap});
                if (trans < 0.1) dt *= 2;
                dt = std::min(dt, t_end - t);
                const double tm = t + 0.5 * dt;
                const Vec3d p = o + dir * tm;
                const double h = m.altitude(p);
                Column col;
                double shape = 0;
                ++full;
                const double d = m.density(p, h, true, &col, &shape);
                if (d > 0) {
                    zero_run = 0;
                    const double sigma = ext * d;
                    const double cap = std::max(kMinCappedStep, kMaxStepTau / (s.quality * sigma));
                    if (dt > 1.5 * cap && tau_cap > cap && trans >= 0.1) {
                        tau_cap = cap; // too deep a step: retake it shorter
                        continue;
                    }
                    tau_cap = cap;
                    const double rain = 1 + sc.rain_absorption * col.precip;
                    // Physical mode: the step is lit where its light comes from,
                    // the mean optical depth into it under the e^-tau weight
                    // (a step at the cloud's surface is often several mean free
                    // paths thick here; its midpoint sits deeper, where the sun
                    // is fainter and the diffuse light stronger).
                    Vec3d pl = p;
                    double hl = h;
                    if (!s.artistic) {
                        const double od = sigma * dt;
                        const double frac = od > 1e-4 ? (1 - od * std::exp(-od) / -std::expm1(-od)) / od : 0.5 - od / 12;
                        pl = o + dir * (t + frac * dt);
                        hl = m.altitude(pl);
                    }
                    // Light: cheap samples once the view ray is optically deep (HZD's 0.3).
                    const bool cheap_light = trans < 0.7 || tm > 15000; // far samples are hazed and small on screen
                    const double tau = ext * (s.artistic ? sun_depth(pl, cheap_light, trans < 0.3 || tm > 15000) : sun_depth_marched(pl)) * rain;
                    const double sky_tau = ext * sky_depth(pl, hl, col) * rain;
                    double sun_w, sky_w, diffuse_sun = -1, sky_field = -1, tbar = -1;
                    if (diffusion) diffusion->radiances(pl, hl, dir * -1.0, diffuse_sun, sky_field, tbar);
                    // The sun's sub-voxel share (diffusion.h).
                    if (diffuse_sun > 0 && tbar > 0) diffuse_sun *= detail::subgrid_sun_factor(std::exp(-tau / rain), tbar);
                    const double dp = detail::saturate(shape);
                    detail::shade(s, st, tau, dp, detail::remap(dp, 0.0, 1.0, 0.25, 0.05), sky_tau, sun_w, sky_w, diffuse_sun);
                    const double haze = sc.haze_distance > 0 ? 1 - std::exp(-tm / sc.haze_distance) : 0.0;
                    const double absorbed = -std::expm1(-sigma * dt);
                    const double w = trans * absorbed;
                    double glow[3] = {0, 0, 0};
                    if (!lights.empty())
                        detail::point_light_radiance(s, lights, light_core2, p, dir, 0.5 * dt,
                                                     [&](const Vec3d& q, const Vec3d& d2, double len) { return light_depth(q, d2, len); }, glow);
                    for (int c = 0; c < 3; ++c) {
                        const double ls = sun_w * s.sun_colour[c] + sky_w * sky.light(c, sky_field) + glow[c];
                        rgb[c] += w * (ls + (double(haze_colour[c]) - ls) * haze);
                    }
                    trans *= std::exp(-sigma * dt);
                    if (trans < s.min_transmittance) return;
                } else if (++zero_run >= 6) {
                    searching = true; // six empty full samples: back to the cheap search
                    tau_cap = std::numeric_limits<double>::infinity();
                }
                entry_cap = std::numeric_limits<double>::infinity();
                t += dt;
            }
        }
    }

    // What lies behind the clouds along dir: sky (with 2D layers) or ground.
    void background(const Vec3d& o, const Vec3d& dir, double out[3]) const {
        const double tg = [&] {
            double t0, t1;
            if (!sphere_roots(o, dir, m.centre(), r_ground, t0, t1) || t0 < 0 || !(t1 > t0)) return -1.0;
            return t0;
        }();
        if (tg >= 0) {
            const Vec3d p = o + dir * tg;
            const Vec3d n = detail::normalized(p - m.centre());
            const double lit = std::max(0.0, dot(n, sun));
            const double haze = sc.haze_distance > 0 ? 1 - std::exp(-tg / sc.haze_distance) : 0.0;
            for (int c = 0; c < 3; ++c) {
                const double g = sc.ground_albedo[c] * (s.sun_colour[c] * lit + sky.ambient[c]);
                out[c] = g + (double(haze_colour[c]) - g) * haze;
            }
            return;
        }
        const double up_t = detail::saturate(dot(dir, cam_up));
        for (int c = 0; c < 3; ++c) out[c] = sky.at(c, up_t);
        for (const SkyLayer& l : sc.sky_layers) {
            const Field2D& tex = *l.texture;
            Bilinear b;
            double fade = 1;
            if (l.mapping == SkyMapping::Cylinder) {
                const double up = dot(dir, cam_up);
                if (!(up > 0)) continue;
                const double pi2 = 2 * std::numbers::pi;
                const double rows = up / std::sqrt(std::max(1e-12, 1 - up * up)) * tex.width() / pi2;
                if (!(rows < tex.height())) continue; // above the strip
                double az = std::atan2(dir[1], dir[0]) / pi2;
                if (az < 0) az += 1;
                axis_wrap(az * tex.width(), tex.width(), b.x0, b.x1, b.tx);
                axis_clamp(rows, tex.height(), b.y0, b.y1, b.ty);
            } else {
                const double t = ray_sphere_exit_or_hit(o, dir, m.centre(), sc.earth_radius + l.altitude);
                if (!(t > 0)) continue;
                const Vec3d p = o + dir * t;
                axis_wrap((p[0] - l.wind[0] * sc.time) / l.tile * tex.width(), tex.width(), b.x0, b.x1, b.tx);
                axis_wrap((p[1] - l.wind[1] * sc.time) / l.tile * tex.height(), tex.height(), b.y0, b.y1, b.ty);
                // Fade toward the horizon where the layer's texels alias.
                fade = detail::saturate(dot(dir, cam_up) * 8.0);
            }
            const double v = lerp2(tex.channel(l.channel).data(), tex.width(), b);
            double a = l.opacity * detail::saturate((v - l.value_min) / (l.value_max - l.value_min)) * fade;
            if (!(a > 0)) continue;
            const double ph = 0.55 + 0.45 * std::min(4.0, detail::hg(dot(dir, sun), 0.5));
            for (int c = 0; c < 3; ++c) {
                const double lc = 0.8 * s.sun_colour[c] * ph * std::max(0.1, sun[2] + 0.2) + 0.6 * sky.ambient[c];
                out[c] += (lc - out[c]) * a;
            }
        }
    }
};

} // namespace

LayerResult render_layer(const LayerScene& scene, const RenderSettings& settings, const ProgressSink* progress) {
    const auto t0 = std::chrono::steady_clock::now();
    detail::check_settings(settings);
    validate_layer_scene(scene);
    LayerModel model(scene, true);
    const double cam_alt = model.altitude(settings.camera.position);
    if (cam_alt < 0) {
        char buf[160];
        std::snprintf(buf, sizeof buf, "render (2.5D): the camera is %.1f m under the ground (inside the Earth of radius %.0f m); raise camera z", -cam_alt,
                      scene.earth_radius);
        throw Error(buf);
    }
    const detail::Sky sky(settings);
    LayerReport report;
    report.base_noise = model.has_base();
    report.detail_noise = model.has_detail();
    report.curl = model.has_curl() && model.has_detail();
    report.wind = scene.wind[0] != 0 || scene.wind[1] != 0 || scene.cloud_top_offset != 0;
    report.precipitation = model.precipitation() && scene.rain_absorption > 0;
    report.anvil = model.has_anvil();
    report.vortex = model.has_vortex();
    report.cone_skipping = model.has_cone();
    report.distance_skipping = model.has_distance();
    report.sky_layers = int(scene.sky_layers.size());
    report.sky_gradient = settings.sky_horizon.has_value();

    const double thickness = std::max(1.0, model.top() - model.bottom());
    // Lights: the given ones, then each light field's flash in order.
    std::vector<PointLight> lights = settings.lights;
    for (const LightField& f : settings.light_fields) {
        auto flash = flash_lights(f);
        lights.insert(lights.end(), flash.begin(), flash.end());
    }
    report.point_lights = int(lights.size());
    std::unique_ptr<LayerDiffusion> diffusion;
    if (detail::diffusion_wanted(settings) && model.any_cloud()) {
        const Vec2d c = diffusion_patch_centre(model, settings.camera, scene.earth_radius);
        // The square's voxels, and as many more of the same size on each side
        // as reach its clouds' edges (kLayerDiffusionPatch): the lattice stays
        // the square's. Measured on the superstorm's exported patch, whose
        // anvil reaches 930 m past the square: its cut edge had no diffuse
        // light (cloud error 10.7% against Cycles, 9.7% with the margin).
        // At most 2 km a side (a coarse map's texels reach far; the voxel count
        // grows by at most 1.56x).
        const double reach = std::min(reach_of(scene), kLayerDiffusionPatch / 8);
        Box2d patch;
        std::array<int, 2> columns{};
        for (int a = 0; a < 2; ++a) {
            const double voxel = kLayerDiffusionPatch / settings.light_grid[size_t(a)];
            const int extra = static_cast<int>(std::ceil(reach / voxel - 1e-9));
            columns[size_t(a)] = settings.light_grid[size_t(a)] + 2 * extra;
            const double half = 0.5 * kLayerDiffusionPatch + extra * voxel;
            patch.min[size_t(a)] = c[size_t(a)] - half;
            patch.max[size_t(a)] = c[size_t(a)] + half;
        }
        // A sun under the patch centre's horizon lights none of it (the
        // flattened patch would take it from below): no term then.
        const Vec3d up = detail::normalized(Vec3d{{c[0], c[1], 0.0}} - model.centre());
        if (dot(detail::normalized(settings.sun_direction), up) > 0)
            diffusion = std::make_unique<LayerDiffusion>(model, settings, patch, columns, scene.earth_radius);
    }
    report.diffusion = diffusion != nullptr;
    // The physical mode marches 4x finer: its time is the diffusion patch's
    // (the march is ~0.1 s of the superstorm's 2.2), and at the look's steps
    // (60 m in the superstorm, 2.4 of its mean free paths) its cloud error
    // against Cycles was 18.7% instead of 16.6% (hzd_weather 9.5 / 9.2%).
    const double step_quality = settings.quality * (settings.artistic ? 1.0 : 4.0);
    LayerIntegrator in{model,
                       scene,
                       settings,
                       detail::normalized(settings.sun_direction),
                       detail::normalized(settings.camera.position - model.centre()),
                       std::clamp(thickness / 96.0, 5.0, 60.0) / step_quality,
                       2500.0, // the step doubles every 2.5 km of distance
                       400.0 / step_quality, // at most 400 m (the search strides half that)
                       step_quality,
                       std::clamp(thickness / 40.0, 20.0, 120.0),
                       scene.earth_radius,
                       scene.earth_radius + model.bottom(),
                       scene.earth_radius + model.top(),
                       // The envelope describes the map; vortex rings turn only the noise inside it.
                       model.has_cone() || model.has_distance(),
                       sky,
                       settings.sky_horizon.value_or(settings.sky_colour),
                       {},
                       lights,
                       25.0, // a 5 m core keeps the inverse square finite at the light
                       diffusion.get()};
    in.detail_step = 2.0 * model.detail_texel() / step_quality;
    in.surface_detail_step = surface_detail_fraction(settings.quality) * in.detail_step;
    // Six fixed directions in [-1, 1]^3 spread the light cone (the talk's noise kernel).
    for (int i = 0; i < 6; ++i)
        for (int a = 0; a < 3; ++a) in.cone_kernel[i][a] = 2.0 * hash_to_unit(hash_coords(0x636f6e65u, i, a)) - 1.0;

    const int w = settings.width, h = settings.height;
    Field2D image({{w, h}}, 4, Box2d{{{0, 0}}, {{double(w), double(h)}}}, {"r", "g", "b", "transmittance"});
    const detail::Pinhole cam(settings);
    // Sample counters: sums of integers, the same whatever the thread order.
    std::atomic<uint64_t> n_cheap{0}, n_full{0}, n_skip{0};
    detail::for_each_pixel(settings, progress, "render (2.5D)", [&](int x, int y, float jitter, uint64_t& samples) {
        const Vec3d dir = cam.dir(x, y);
        double rgb[3], trans, unused;
        uint64_t c = 0, f = 0, k = 0;
        if (model.any_cloud()) in.trace(settings.camera.position, dir, jitter, rgb, trans, unused, c, f, k);
        else rgb[0] = rgb[1] = rgb[2] = 0, trans = 1;
        double bg[3];
        in.background(settings.camera.position, dir, bg);
        for (int ch = 0; ch < 3; ++ch) image.at(ch, x, y) = static_cast<float>(rgb[ch] + trans * bg[ch]);
        image.at(3, x, y) = static_cast<float>(trans);
        n_cheap.fetch_add(c, std::memory_order_relaxed);
        n_full.fetch_add(f, std::memory_order_relaxed);
        n_skip.fetch_add(k, std::memory_order_relaxed);
        samples += c + f;
    });
    report.cheap_samples = n_cheap.load();
    report.full_samples = n_full.load();
    report.skipped_steps = n_skip.load();
    report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return {std::move(image), report};
}

std::vector<double> layer_density(const LayerScene& scene, const std::vector<Vec3d>& points) {
    validate_layer_scene(scene);
    const LayerModel m(scene);
    std::vector<double> d(points.size(), 0.0);
    for (size_t i = 0; i < points.size(); ++i) d[i] = m.density(points[i], m.altitude(points[i]), true);
    return d;
}

std::vector<double> layer_mean_density(const LayerScene& scene, const std::vector<Vec3d>& points) {
    validate_layer_scene(scene);
    const LayerModel m(scene, true);
    std::vector<double> d(points.size(), 0.0);
    for (size_t i = 0; i < points.size(); ++i) d[i] = m.mean_density(points[i], m.altitude(points[i]));
    return d;
}

LayerShell layer_shell(const LayerScene& scene) {
    validate_layer_scene(scene);
    const LayerModel m(scene);
    return {m.bottom(), m.top()};
}

double layer_reach(const LayerScene& scene) {
    validate_layer_scene(scene);
    return reach_of(scene);
}

Camera layer_camera(const LayerScene& scene, LayerView view, double aspect, double azimuth_deg, double elevation_deg) {
    validate_layer_scene(scene);
    LayerModel m(scene);
    const Box2d& b = scene.ndf->bounds();
    const double cx = 0.5 * (b.min[0] + b.max[0]), cy = 0.5 * (b.min[1] + b.max[1]);
    const double sx = b.max[0] - b.min[0], sy = b.max[1] - b.min[1];
    const double mid = 0.5 * (m.bottom() + m.top());
    const double deg = std::numbers::pi / 180;
    Camera c;
    c.up = {{0, 0, 1}};
    switch (view) {
    case LayerView::Ground: {
        c.fov_deg = 60;
        c.position = {{cx, b.min[1] + 0.15 * sy, 2.0}};
        c.look_at = c.position + Vec3d{{0, std::cos(20 * deg), std::sin(20 * deg)}};
        break;
    }
    case LayerView::Aerial: {
        c.fov_deg = 60;
        c.position = {{cx, b.min[1] + 0.1 * sy, m.top() + 1500}};
        c.look_at = c.position + Vec3d{{0, std::cos(20 * deg), -std::sin(20 * deg)}};
        break;
    }
    case LayerView::Orbit: {
        // Frame the cloud mass, not the map: the centroid and spread of
        // coverage x thickness^2 (tall storms dominate a fair-weather field).
        const Field2D& f = *scene.ndf;
        const int cc = f.find_channel("coverage"), cmn = f.find_channel("min_height"), cmx = f.find_channel("max_height");
        double sw = 0, sx1 = 0, sy1 = 0, sx2 = 0, sy2 = 0;
        for (int y = 0; y < f.height(); ++y)
            for (int x = 0; x < f.width(); ++x) {
                const double t = std::max(0.0, double(f.at(cmx, x, y)) - f.at(cmn, x, y));
                const double wgt = std::max(0.0, double(f.at(cc, x, y))) * t * t;
                const Vec2d p = f.texel_center(x, y);
                sw += wgt, sx1 += wgt * p[0], sy1 += wgt * p[1], sx2 += wgt * p[0] * p[0], sy2 += wgt * p[1] * p[1];
            }
        double mx = cx, my = cy, r = 0.5 * std::hypot(sx, sy);
        if (sw > 0) {
            mx = sx1 / sw, my = sy1 / sw;
            const double var = std::max(0.0, sx2 / sw - mx * mx) + std::max(0.0, sy2 / sw - my * my);
            r = std::clamp(std::sqrt(var), 2000.0, r);
        }
        c.fov_deg = 50;
        const double half = 0.5 * c.fov_deg * deg;
        const double half_min = std::min(half, std::atan(std::tan(half) * aspect));
        const double radius = std::hypot(r, 0.5 * (m.top() - m.bottom()));
        const double dist = radius / std::sin(half_min);
        const double az = azimuth_deg * deg, el = elevation_deg * deg;
        c.look_at = {{mx, my, mid}};
        // Azimuth 0 = from -y, counter-clockwise seen from above (framing_camera's convention).
        c.position = c.look_at + Vec3d{{std::sin(az) * std::cos(el) * dist, -std::cos(az) * std::cos(el) * dist, std::sin(el) * dist}};
        if (c.position[2] < 2) c.position[2] = 2;
        break;
    }
    }
    return c;
}

Field3DPtr layer_flash_probability(const Field2D& map, int channel, double z_min, double z_max) {
    if (channel < 0 || channel >= map.channels()) throw Error("render (2.5D): flash probability channel " + std::to_string(channel) + " out of range");
    if (!(std::isfinite(z_min) && std::isfinite(z_max) && z_max > z_min)) throw Error("render (2.5D): flash heights need z_max > z_min, finite");
    const Box2d& b = map.bounds();
    auto f = std::make_shared<Field3D>(Vec3i{{map.width(), map.height(), 1}}, 1, Box3d{{{b.min[0], b.min[1], z_min}}, {{b.max[0], b.max[1], z_max}}},
                                       std::vector<std::string>{"probability"});
    auto src = map.channel(channel);
    std::copy(src.begin(), src.end(), f->channel(0).begin());
    return f;
}

Field2D composite_over(const Field2D& front, const Field2D& back, const RenderSettings& settings) {
    if (front.width() != back.width() || front.height() != back.height() || front.channels() < 4 || back.channels() < 4)
        throw Error("render: composite_over needs two r, g, b, transmittance images of the same size");
    if (front.width() != settings.width || front.height() != settings.height) throw Error("render: composite_over: the images do not match the settings' size");
    const detail::Sky sky(settings);
    const detail::Pinhole cam(settings);
    Field2D out = back;
    for (int y = 0; y < front.height(); ++y)
        for (int x = 0; x < front.width(); ++x) {
            const double t = front.at(3, x, y);
            const double up_t = detail::saturate(cam.dir(x, y)[2]);
            for (int c = 0; c < 3; ++c) {
                const double clouds = double(front.at(c, x, y)) - t * sky.at(c, up_t); // the front's own clouds
                out.at(c, x, y) = static_cast<float>(clouds + t * double(back.at(c, x, y)));
            }
            out.at(3, x, y) = static_cast<float>(t * double(back.at(3, x, y)));
        }
    return out;
}

} // namespace atlas::render

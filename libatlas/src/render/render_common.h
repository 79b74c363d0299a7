// Internal: what the voxel ray-marcher (renderer.cpp) and the 2.5D layer
// ray-marcher (layer.cpp) share: settings checks, the phase function, the
// Nubis lighting of one sample (Beer-powder, dual HG, ambient, multiple
// scattering), the pinhole camera and the deterministic 16x16-tile TBB loop.
#pragma once

#include "cloud_sampler.h"

#include "atlas/core/error.h"
#include "atlas/core/hash.h"
#include "atlas/core/parallel.h"
#include "atlas/core/progress.h"
#include "atlas/render/renderer.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

namespace atlas::render::detail {

// Linear-interpolation weights along one axis for a continuous texel coordinate u
// (texel centres at i + 0.5): clamped to the grid, or wrapped (tiling textures).
inline void axis_clamp(double u, int n, int& i0, int& i1, float& t) {
    u -= 0.5;
    if (u <= 0) { i0 = i1 = 0; t = 0; return; }
    if (u >= n - 1) { i0 = i1 = n - 1; t = 0; return; }
    i0 = static_cast<int>(u);
    i1 = i0 + 1;
    t = static_cast<float>(u - i0);
}

inline void axis_wrap(double u, int n, int& i0, int& i1, float& t) {
    u -= 0.5;
    const double f = std::floor(u);
    t = static_cast<float>(u - f);
    long long i = static_cast<long long>(f) % n;
    if (i < 0) i += n;
    i0 = static_cast<int>(i);
    i1 = i0 + 1 == n ? 0 : i0 + 1;
}

inline bool finite3(const Vec3d& v) { return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]); }

inline Vec3d normalized(const Vec3d& v) { return v / length(v); }

// Throws atlas::Error ("render: ...") naming the first bad setting.
void check_settings(const RenderSettings& s);

inline double hg(double cos_theta, double g) {
    // Normalised so that the isotropic phase (g = 0) is 1 rather than 1/(4 pi).
    const double denom = 1 + g * g - 2 * g * cos_theta;
    return (1 - g * g) / (denom * std::sqrt(denom));
}

inline double remap(double v, double a, double b, double c, double d) {
    const double t = saturate((v - a) / (b - a));
    return c + (d - c) * t;
}

// GPU Pro 7's Remap: (v - a) / (b - a) * (d - c) + c, not clamped.
inline double remap_unclamped(double v, double a, double b, double c, double d) { return c + (v - a) / (b - a) * (d - c); }

inline double dual_hg(const RenderSettings& s, double cos_theta) {
    return s.hg_forward_weight * hg(cos_theta, s.hg_forward) + (1 - s.hg_forward_weight) * hg(cos_theta, s.hg_back);
}

// Per-ray constants of the sun lighting (cos = dot(view, sun)).
struct SunTerms {
    double sun_phase;  // dual-lobe HG
    double powder_mix; // 0.5 + 0.5 cos: no powder darkening looking toward the sun
    double ms_sun;     // clamp(cos, 0, 0.9)
    std::array<double, 16> ms_phase{}; // physical mode: the octaves' phase (g x ms_anisotropy^n)
};

// Whether the settings ask for the diffusion term (diffusion.h): the physical
// model with octaves and multiple scattering on; and the phase function's
// mean cosine it diffuses with (the dual lobe's).
inline bool diffusion_wanted(const RenderSettings& s) { return !s.artistic && s.ms_diffusion && s.ms_octaves > 0 && s.multiple_scattering > 0; }
inline double phase_mean_cosine(const RenderSettings& s) { return s.hg_forward_weight * s.hg_forward + (1 - s.hg_forward_weight) * s.hg_back; }

inline SunTerms sun_terms(const RenderSettings& s, double cos_theta) {
    SunTerms t{dual_hg(s, cos_theta), 0.5 + 0.5 * cos_theta, std::clamp(cos_theta, 0.0, 0.9), {}};
    if (!s.artistic) {
        double c = 1;
        for (int n = 1; n <= s.ms_octaves; ++n) {
            c *= s.ms_anisotropy;
            t.ms_phase[size_t(n - 1)] = s.hg_forward_weight * hg(cos_theta, s.hg_forward * c) + (1 - s.hg_forward_weight) * hg(cos_theta, s.hg_back * c);
        }
    }
    return t;
}

// The Nubis lighting of one sample: weights of the sun colour and of the
// ambient sky colour in the in-scattered radiance.
//   tau         optical depth toward the sun
//   dp          the sample's profile (in-scatter probability), [0, 1]
//   ms_relax    Beer relaxation deep inside (0.05 deep .. 0.25 at the surface)
//   sky_tau     optical depth toward the sky
//   diffusion   the diffusion term's in-scattered weight at the sample
//               (DiffusionGrid::radiances' sun; physical mode with ms_diffusion),
//               < 0 without it
inline void shade(const RenderSettings& s, const SunTerms& st, double tau, double dp, double ms_relax, double sky_tau, double& sun_w,
                  double& sky_w, double diffusion = -1) {
    if (!s.artistic) {
        // The physical model (docs/render.md, "Reference: Cycles"): single
        // scattering of the sun plus the octave series; st.ms_phase[n] holds
        // the dual-lobe phase with both g scaled by ms_anisotropy^n.
        double direct = std::exp(-tau) * st.sun_phase, ms = 0, a = 1, b = 1;
        for (int n = 1; n <= s.ms_octaves; ++n) {
            a *= s.ms_energy;
            b *= s.ms_extinction;
            ms += a * std::exp(-b * tau) * st.ms_phase[size_t(n - 1)];
        }
        // Light scatters again only where there is medium around the sample:
        // the octaves are weighted by the probability of a further scattering
        // event along the two paths we know, toward the sun and the zenith.
        const double q = -std::expm1(-(tau + sky_tau));
        const double again = s.ms_scatter_power == 1 ? q : std::pow(q, s.ms_scatter_power);
        // With the diffusion term: the larger of the octaves and its P1
        // in-scattered radiance (docs/render.md, "Multiple scattering by
        // diffusion"): each falls short outside its regime (the octaves
        // around thick media, diffusion in wisps a few mean free paths
        // across), neither was measured above Cycles where the other holds.
        double multi = ms * again;
        if (diffusion >= 0) multi = std::max(multi, diffusion);
        sun_w = direct + s.multiple_scattering * multi;
        sky_w = s.ambient_strength * (s.ms_octaves > 0 ? 1.0 : std::exp(-sky_tau));
        return;
    }
    const double beer = std::exp(-tau);
    const double powder = 1 - std::exp(-2 * tau);
    const double direct = beer * (powder + (1 - powder) * st.powder_mix) * st.sun_phase;
    // tau is infinite where the Earth hides the sun: no light, not inf x 0.
    const double ms = std::isinf(tau) ? 0.0 : dp * std::exp(-tau * remap(st.ms_sun, 0.0, 0.9, 0.25, ms_relax));
    const double amb = std::sqrt(1 - dp) * std::exp(-sky_tau * s.sky_occlusion);
    sun_w = direct + s.multiple_scattering * ms;
    sky_w = s.ambient_strength * amb;
}

// 1 / (d^2 + core^2) averaged over the ray's step [p - half view, p + half
// view] (to = light - p, d2 = |to|^2 + core^2): the closed form of the
// inverse square along a line, atan. Read at the step's midpoint only, a
// step passing a flash's core sampled it at a random distance: fireflies
// around every flash that 16x the steps still showed.
inline double mean_inverse_square(const Vec3d& to, const Vec3d& view, double half_step, double d2) {
    const double along = dot(to, view); // the light's offset along the ray from p
    const double h2 = d2 - along * along; // squared distance from the line, with the core
    if (!(half_step > 1e-9 * std::sqrt(d2)) || !(h2 > 0)) return 1.0 / d2;
    const double hl = std::sqrt(h2);
    return (std::atan((half_step - along) / hl) + std::atan((half_step + along) / hl)) / (hl * 2 * half_step);
}

// In-scattered radiance weight per channel at p from every point light
// (lights.h: inverse square with a core averaged over the step of
// half_step either side of p, the radius window, Beer toward the
// light from depth(p, dir, r) = summed density x metres, dual-lobe HG; at
// the light itself isotropic).
template <class DepthFn>
void point_light_radiance(const RenderSettings& s, const std::vector<PointLight>& lights, double core2, const Vec3d& p, const Vec3d& view,
                          double half_step, DepthFn&& depth, double out[3]) {
    out[0] = out[1] = out[2] = 0;
    for (const PointLight& l : lights) {
        const Vec3d to = l.position - p;
        const double r2 = dot(to, to), r = std::sqrt(r2);
        double window = 1;
        if (l.radius > 0) {
            if (r >= l.radius) continue;
            const double q = r2 / (l.radius * l.radius);
            window = (1 - q * q) * (1 - q * q);
        }
        const double energy = l.intensity * window * mean_inverse_square(to, view, half_step, r2 + core2);
        if (!(energy > 0)) continue;
        // At the light itself the direction is undefined: isotropic there.
        const Vec3d dir = r > 0 ? to / r : view;
        const double cos_theta = r > 0 ? dot(view, dir) : 0.0;
        double beer = 1.0;
        if (r > 0) {
            const double tau = s.extinction * depth(p, dir, r);
            beer = std::exp(-tau);
            if (s.artistic) {
                // The look: light from a flash inside a storm diffuses out
                // through the cloud instead of dying as exp(-tau) (the
                // octaves of the sun's physical term, each added above the
                // Beer term so optically thin glow keeps its closed form).
                // Beer alone left a storm's in-cloud flashes invisible.
                double a = 1, b = 1, extra = 0;
                for (int n = 1; n <= kPhysicalMsOctaves; ++n) {
                    a *= s.ms_energy;
                    b *= s.ms_extinction;
                    extra += a * std::max(0.0, std::exp(-b * tau) - beer);
                }
                beer += extra;
            }
        }
        const double w = energy * beer * dual_hg(s, cos_theta);
        for (int c = 0; c < 3; ++c) out[c] += w * l.colour[c];
    }
}

// The sky: zenith and horizon colour; the same colour twice is the uniform
// sky (h + (z - h) * t == h exactly, so the uniform look keeps its bytes).
struct Sky {
    Vec3f zenith, horizon;
    double ambient[3]; // cosine-weighted upper-hemisphere mean

    explicit Sky(const RenderSettings& s) : zenith(s.sky_colour), horizon(s.sky_horizon.value_or(s.sky_colour)) {
        // Physical mode: the mean over the whole sphere (the horizon colour
        // below the horizon, mean saturate(z) = 1/4), which multiple
        // scattering spreads through a cloud.
        const double k = s.artistic ? 2.0 / 3.0 : 0.25;
        for (int c = 0; c < 3; ++c) ambient[c] = double(horizon[c]) + (double(zenith[c]) - double(horizon[c])) * k;
    }
    double at(int c, double up_t) const { return double(horizon[c]) + (double(zenith[c]) - double(horizon[c])) * up_t; }
    // The sky's light in a cloud: with the diffusion's sky field (its weight
    // field >= 0, DiffusionGrid::radiances' sky) lerp(horizon, zenith, field),
    // else (field < 0: no field there) the ambient mean.
    double light(int c, double field) const { return field >= 0 ? at(c, field) : ambient[c]; }
};

// The pinhole camera of the settings: the view direction of pixel (x, y),
// y = 0 the bottom row.
struct Pinhole {
    Vec3d fwd, right, up;
    double half_w, half_h;
    int w, h;

    explicit Pinhole(const RenderSettings& s) : w(s.width), h(s.height) {
        fwd = normalized(s.camera.look_at - s.camera.position);
        right = normalized(cross(fwd, s.camera.up));
        up = cross(right, fwd);
        half_h = std::tan(0.5 * s.camera.fov_deg * std::numbers::pi / 180);
        half_w = half_h * double(w) / double(h);
    }
    Vec3d dir(int x, int y) const {
        const double u = (2 * (x + 0.5) / w - 1) * half_w;
        const double v = (2 * (y + 0.5) / h - 1) * half_h;
        return normalized(fwd + right * u + up * v);
    }
};

constexpr int kTile = 16;

// The deterministic tile loop: fixed 16x16 tiles, one block each; pixel(x, y,
// jitter, samples) is called once per pixel with jitter =
// hash_to_unit(hash_coords(seed, x, y)) and must depend only on its
// arguments. Returns the summed per-tile sample counts (fixed order).
// Progress per tile under `task`; throws CancelledError on cancel.
template <class PixelFn>
uint64_t for_each_pixel(const RenderSettings& s, const ProgressSink* progress, const std::string& task, PixelFn&& pixel) {
    const int w = s.width, h = s.height;
    const int tiles_x = (w + kTile - 1) / kTile, tiles_y = (h + kTile - 1) / kTile;
    const int tiles = tiles_x * tiles_y;
    std::vector<uint64_t> tile_samples(size_t(tiles), 0);
    std::atomic<int> done{0};
    std::atomic<bool> cancelled{false};
    with_thread_limit(s.threads, [&] {
        parallel_blocks(size_t(tiles), 1, [&](size_t t0, size_t t1) {
            for (int ti = int(t0); ti != int(t1); ++ti) {
                if (cancelled.load(std::memory_order_relaxed)) return;
                if (progress && progress->cancelled()) {
                    cancelled = true;
                    return;
                }
                const int x0 = (ti % tiles_x) * kTile, y0 = (ti / tiles_x) * kTile;
                uint64_t samples = 0;
                for (int y = y0; y < std::min(h, y0 + kTile); ++y)
                    for (int x = x0; x < std::min(w, x0 + kTile); ++x)
                        pixel(x, y, hash_to_unit(hash_coords(s.seed, x, y)), samples);
                tile_samples[size_t(ti)] = samples;
                const int n = ++done;
                if (progress && progress->on_progress) {
                    ProgressEvent e;
                    e.task = task;
                    e.done = n;
                    e.total = tiles;
                    e.fraction = double(n) / tiles;
                    progress->on_progress(e);
                }
            }
        });
    });
    if (cancelled) throw CancelledError();
    uint64_t total = 0;
    for (uint64_t v : tile_samples) total += v;
    return total;
}

} // namespace atlas::render::detail

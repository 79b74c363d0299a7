// The 2.5D ray march (layer_march.h).
#include "layer_march.h"

#include <cmath>

namespace atlas::render::layer_detail {

// The ray from p toward the sun meets the ground sphere ahead of p.
bool LayerIntegrator::earth_hides_sun(const Vec3d& p) const {
    double g0, g1;
    return sphere_roots(p, sun, m.centre(), r_ground, g0, g1) && g0 >= 0 && g1 > g0;
}

// Summed density toward a point light `len` metres away: light_samples cheap samples.
double LayerIntegrator::light_depth(const Vec3d& p, const Vec3d& d, double len) const {
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
double LayerIntegrator::sun_depth(const Vec3d& p, bool cheap, bool coarse) const {
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
double LayerIntegrator::sun_depth_marched(const Vec3d& p) const {
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
double LayerIntegrator::sky_depth(const Vec3d& p, double h, const Column& c) const {
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
double LayerIntegrator::step_at(double t, double t0) const {
    const double td = s.artistic ? t : t - t0;
    return std::min(std::max(max_step, 0.01 * td / step_quality), base_step * (1 + td / grow));
}

void LayerIntegrator::trace(const Vec3d& o, const Vec3d& dir, float jitter, double rgb[3], double& trans, double& bg_weight_t, uint64_t& cheap,
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
void LayerIntegrator::background(const Vec3d& o, const Vec3d& dir, double out[3]) const {
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

} // namespace atlas::render::layer_detail

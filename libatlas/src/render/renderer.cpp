#include "atlas/render/renderer.h"

#include "cloud_sampler.h"
#include "light_grid.h"

#include "atlas/core/error.h"
#include "atlas/core/hash.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <memory>
#include <numbers>
#include <optional>

namespace atlas::render {

std::vector<std::string> RenderReport::active_features() const {
    std::vector<std::string> f;
    if (noise_uprez) f.push_back("noise_uprez");
    if (billowy) f.push_back("billowy");
    if (near_camera_detail) f.push_back("near_camera_detail");
    if (sdf_skipping) f.push_back("sdf_skipping");
    f.push_back(light_grid ? "light_grid" : "marched_light");
    f.push_back("beer_powder");
    f.push_back("dual_hg");
    f.push_back("ambient");
    f.push_back("multiple_scattering");
    if (point_lights) f.push_back("point_lights");
    if (sky_gradient) f.push_back("sky_gradient");
    return f;
}

namespace {

constexpr int kTile = 16;

bool finite3(const Vec3d& v) { return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]); }

Vec3d normalized(const Vec3d& v) { return v / length(v); }

void check_settings(const RenderSettings& s) {
    auto bad = [](const std::string& what) { throw Error("render: " + what); };
    if (s.width <= 0 || s.height <= 0)
        bad("image size must be at least 1x1 pixels, got " + std::to_string(s.width) + "x" + std::to_string(s.height));
    if (uint64_t(s.width) * uint64_t(s.height) > (uint64_t(1) << 28)) bad("image size is too large (more than 2^28 pixels)");
    if (!finite3(s.camera.position)) bad("camera.position must be finite");
    if (!finite3(s.camera.look_at)) bad("camera.look_at must be finite");
    if (!finite3(s.camera.up)) bad("camera.up must be finite");
    const Vec3d fwd = s.camera.look_at - s.camera.position;
    if (!(length(fwd) > 0)) bad("camera.look_at must differ from camera.position");
    if (!(length(cross(fwd, s.camera.up)) > 1e-9 * length(fwd) * length(s.camera.up)))
        bad("camera.up must not be parallel to the view direction");
    if (!(s.camera.fov_deg > 0 && s.camera.fov_deg < 180)) bad("camera.fov_deg must be in (0, 180), got " + std::to_string(s.camera.fov_deg));
    if (!finite3(s.sun_direction) || !(length(s.sun_direction) > 0)) bad("sun_direction must be a finite non-zero vector");
    for (int i = 0; i < 3; ++i) {
        if (!(s.sun_colour[i] >= 0) || !std::isfinite(s.sun_colour[i])) bad("sun_colour must be finite and >= 0");
        if (!(s.sky_colour[i] >= 0) || !std::isfinite(s.sky_colour[i])) bad("sky_colour must be finite and >= 0");
        if (s.sky_horizon && (!((*s.sky_horizon)[i] >= 0) || !std::isfinite((*s.sky_horizon)[i])))
            bad("sky_horizon must be finite and >= 0");
        if (s.light_grid[i] < 1 || s.light_grid[i] > 1024) bad("light_grid must be 1..1024 voxels per axis");
    }
    if (!(s.quality > 0) || !std::isfinite(s.quality) || s.quality > 64) bad("quality must be in (0, 64]");
    if (!(s.extinction >= 0) || !std::isfinite(s.extinction)) bad("extinction must be finite and >= 0 (per metre)");
    if (!(std::fabs(s.hg_forward) < 1) || !(std::fabs(s.hg_back) < 1)) bad("hg_forward and hg_back must be in (-1, 1)");
    if (!(s.hg_forward_weight >= 0 && s.hg_forward_weight <= 1)) bad("hg_forward_weight must be in [0, 1]");
    if (!(s.ambient_strength >= 0) || !std::isfinite(s.ambient_strength)) bad("ambient_strength must be finite and >= 0");
    if (!(s.multiple_scattering >= 0) || !std::isfinite(s.multiple_scattering)) bad("multiple_scattering must be finite and >= 0");
    if (!(s.reference_step >= 0) || !std::isfinite(s.reference_step)) bad("reference_step must be finite and >= 0 (0 = automatic)");
    if (!(s.min_transmittance >= 0 && s.min_transmittance < 1)) bad("min_transmittance must be in [0, 1)");
    if (s.threads < 0) bad("threads must be >= 0 (0 = all cores)");
    if (s.light_samples < 1 || s.light_samples > 64) bad("light_samples must be 1..64");
    for (size_t i = 0; i < s.lights.size(); ++i) validate_light(s.lights[i], "lights[" + std::to_string(i) + "]");
}

double hg(double cos_theta, double g) {
    // Normalised so that the isotropic phase (g = 0) is 1 rather than 1/(4 pi).
    const double denom = 1 + g * g - 2 * g * cos_theta;
    return (1 - g * g) / (denom * std::sqrt(denom));
}

double remap(double v, double a, double b, double c, double d) {
    const double t = detail::saturate((v - a) / (b - a));
    return c + (d - c) * t;
}

// Entry and exit distances of a ray in the box; nullopt on a miss.
std::optional<std::pair<double, double>> clip_ray(const Box3d& b, const Vec3d& o, const Vec3d& d) {
    double t0 = 0, t1 = std::numeric_limits<double>::infinity();
    for (int a = 0; a < 3; ++a) {
        if (std::fabs(d[a]) < 1e-15) {
            if (o[a] < b.min[a] || o[a] > b.max[a]) return std::nullopt;
            continue;
        }
        double ta = (b.min[a] - o[a]) / d[a], tb = (b.max[a] - o[a]) / d[a];
        if (ta > tb) std::swap(ta, tb);
        t0 = std::max(t0, ta);
        t1 = std::min(t1, tb);
    }
    if (!(t1 > t0)) return std::nullopt;
    return std::make_pair(t0, t1);
}

struct Integrator {
    const detail::CloudSampler& cloud;
    const detail::LightGrid* grid; // null in reference mode
    const RenderSettings& s;
    Vec3d sun;       // unit, toward the sun
    double base_step; // metres at the camera
    double grow;      // metres of distance per extra base step
    double light_step;
    double ref_step;
    bool near_detail;
    double ambient[3];                // sky light reaching the cloud, per channel
    const std::vector<PointLight>& lights;
    double light_core2;               // squared core radius of the inverse-square falloff

    double phase(double cos_theta) const {
        return s.hg_forward_weight * hg(cos_theta, s.hg_forward) + (1 - s.hg_forward_weight) * hg(cos_theta, s.hg_back);
    }

    double march_density(const Vec3d& p, const Vec3d& dir, double step, double max_len = 1e300) const {
        const double len = std::min(max_len, detail::exit_distance(cloud.bounds(), p, dir));
        const int n = static_cast<int>(std::ceil(len / step));
        double acc = 0;
        for (int i = 0; i < n; ++i) {
            const double t0 = i * step, dt = std::min(step, len - t0);
            const Vec3d q = p + dir * (t0 + 0.5 * dt);
            acc += cloud.density_at(q[0], q[1], q[2], 1e30) * dt;
        }
        return acc;
    }

    // Summed density (density x metres) toward the sun and toward the sky.
    void light_depths(const Vec3d& p, double& sun_sum, double& sky_sum) const {
        if (!grid) {
            sun_sum = march_density(p, sun, 2 * ref_step);
            sky_sum = march_density(p, Vec3d{{0, 0, 1}}, 2 * ref_step);
            return;
        }
        // The first two samples are taken explicitly (detail near surfaces),
        // the rest of the way comes from the voxel light grid.
        const double l = light_step;
        double acc = 0;
        for (int i = 0; i < 2; ++i) {
            const Vec3d q = p + sun * ((i + 0.5) * l);
            acc += cloud.density_at(q[0], q[1], q[2], 1e30) * l;
        }
        const Vec3d q = p + sun * (2 * l);
        acc += grid->sun(q[0], q[1], q[2]);
        sun_sum = acc;
        sky_sum = grid->sky(p[0], p[1], p[2]);
    }

    // Summed density (density x metres) from p toward a light `len` metres
    // away along unit `dir`, inside the volume only.
    double light_depth(const Vec3d& p, const Vec3d& dir, double len) const {
        if (!grid) return march_density(p, dir, 2 * ref_step, len);
        const double seg = std::min(len, detail::exit_distance(cloud.bounds(), p, dir));
        const int n = s.light_samples;
        double acc = 0;
        for (int i = 0; i < n; ++i) {
            const Vec3d q = p + dir * ((i + 0.5) * seg / n);
            acc += cloud.density_at(q[0], q[1], q[2], 1e30);
        }
        return acc * seg / n;
    }

    // In-scattered radiance weight per channel from every point light at p
    // (inverse square, window, Beer toward the light, dual-lobe HG).
    void point_light_radiance(const Vec3d& p, const Vec3d& view, double out[3]) const {
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
            const double energy = l.intensity * window / (r2 + light_core2);
            if (!(energy > 0)) continue;
            // At the light itself the direction is undefined: isotropic there.
            const Vec3d dir = r > 0 ? to / r : view;
            const double cos_theta = r > 0 ? dot(view, dir) : 0.0;
            const double beer = r > 0 ? std::exp(-s.extinction * light_depth(p, dir, r)) : 1.0;
            const double w = energy * beer * phase(cos_theta);
            for (int c = 0; c < 3; ++c) out[c] += w * l.colour[c];
        }
    }

    // Returns radiance (clouds only) and transmittance along one ray.
    // kLights: compiled with the point-light term only when the scene has lights.
    template <bool kLights>
    void trace(const Vec3d& o, const Vec3d& dir, float jitter, double rgb[3], double& trans, uint64_t& samples) const {
        rgb[0] = rgb[1] = rgb[2] = 0;
        trans = 1;
        const auto hit = clip_ray(cloud.bounds(), o, dir);
        if (!hit) return;
        const double cos_theta = dot(dir, sun);
        const double sun_phase = phase(cos_theta);
        const double powder_mix = 0.5 + 0.5 * cos_theta; // no powder darkening looking toward the sun
        const double ms_sun = std::clamp(cos_theta, 0.0, 0.9);
        const double ext = s.extinction;
        const double min_t = s.min_transmittance;
        double t = hit->first;
        const double t_end = hit->second;
        bool first = true;
        while (t < t_end) {
            double dt;
            if (grid) {
                dt = base_step * (1 + t / grow);
                // Sphere tracing: skip the SDF's empty ball when it is longer than the step.
                const Vec3d p = o + dir * t;
                const float sdf = cloud.voxel(p[0], p[1], p[2]).sdf;
                if (sdf > dt) {
                    t += sdf;
                    continue;
                }
            } else {
                dt = ref_step;
            }
            if (first) dt *= 0.5 + 0.5 * jitter; // jittered start decorrelates banding
            first = false;
            dt = std::min(dt, t_end - t);
            const double tm = t + 0.5 * dt;
            const Vec3d p = o + dir * tm;
            const detail::VoxelSample v = cloud.voxel(p[0], p[1], p[2]);
            ++samples;
            if (v.sdf < 0) {
                const double d = cloud.density(v, p[0], p[1], p[2], near_detail ? tm : 1e30);
                const double sigma = ext * d;
                if (sigma > 0) {
                    double sun_sum, sky_sum;
                    light_depths(p, sun_sum, sky_sum);
                    const double tau = ext * sun_sum;
                    const double beer = std::exp(-tau);
                    const double powder = 1 - std::exp(-2 * tau);
                    const double direct = beer * (powder + (1 - powder) * powder_mix) * sun_phase;
                    const double dp = detail::saturate(v.profile);
                    const double ms = dp * std::exp(-tau * remap(ms_sun, 0.0, 0.9, 0.25, remap(v.sdf, -128.0, 0.0, 0.05, 0.25)));
                    const double amb = std::sqrt(1 - dp) * std::exp(-ext * sky_sum);
                    const double sun_w = direct + s.multiple_scattering * ms;
                    const double sky_w = s.ambient_strength * amb;
                    // Energy-conserving step integral: (1 - exp(-sigma dt)) of the
                    // light is scattered toward the eye (albedo 1).
                    const double absorbed = -std::expm1(-sigma * dt);
                    const double w = trans * absorbed;
                    for (int c = 0; c < 3; ++c) rgb[c] += w * (sun_w * s.sun_colour[c] + sky_w * ambient[c]);
                    if constexpr (kLights) {
                        double glow[3];
                        point_light_radiance(p, dir, glow);
                        for (int c = 0; c < 3; ++c) rgb[c] += w * glow[c];
                    }
                    trans *= std::exp(-sigma * dt);
                    if (trans < min_t) break; // the rest is invisible
                }
            }
            t += dt;
        }
    }
};

} // namespace

RenderResult render_clouds(const CloudScene& scene, const RenderSettings& settings, const ProgressSink* progress) {
    check_settings(settings);
    detail::CloudSampler cloud(scene);
    const bool fast = settings.mode == RenderMode::Fast;
    const Vec3d sun = normalized(settings.sun_direction);
    // Lights: the given ones, then each light field's flash in order.
    std::vector<PointLight> lights = settings.lights;
    for (const LightField& f : settings.light_fields) {
        auto flash = flash_lights(f);
        lights.insert(lights.end(), flash.begin(), flash.end());
    }
    // Sky: zenith and horizon; the same colour twice is the uniform sky
    // (h + (z - h) * t == h exactly, so the uniform look keeps its bytes).
    const Vec3f zenith = settings.sky_colour, horizon = settings.sky_horizon.value_or(settings.sky_colour);

    RenderReport report;
    report.point_lights = !lights.empty();
    report.point_light_count = int(lights.size());
    report.sky_gradient = settings.sky_horizon.has_value();
    report.noise_uprez = cloud.has_noise();
    report.billowy = cloud.has_noise() && cloud.billowy();
    report.sdf_skipping = fast;
    report.light_grid = fast;
    {
        // Near-camera detail only matters when the camera is within its 198 m range.
        const Box3d& b = cloud.bounds();
        double d2 = 0;
        for (int a = 0; a < 3; ++a) {
            const double c = settings.camera.position[a];
            const double e = c < b.min[a] ? b.min[a] - c : (c > b.max[a] ? c - b.max[a] : 0.0);
            d2 += e * e;
        }
        report.near_camera_detail = cloud.has_noise() && std::sqrt(d2) < 198.0;
    }

    const Vec3d vox = cloud.voxel_size();
    const double vmin = std::min({vox[0], vox[1], vox[2]});
    std::unique_ptr<detail::LightGrid> grid;
    auto run = [&](auto&& f) {
        if (settings.threads > 0) {
            tbb::task_arena arena(settings.threads);
            arena.execute(f);
        } else {
            f();
        }
    };
    // The light grid never needs to be finer than the volume itself.
    Vec3i grid_res = settings.light_grid;
    for (int a = 0; a < 3; ++a) grid_res[a] = std::min(grid_res[a], scene.modeling->resolution()[a]);
    if (fast) run([&] { grid = std::make_unique<detail::LightGrid>(cloud, grid_res, sun); });

    Integrator in{cloud,
                  grid.get(),
                  settings,
                  sun,
                  0.5 * vmin / settings.quality,
                  128 * vmin, // the step doubles every 128 voxels of distance
                  grid ? 0.5 * grid->voxel_min() : 0.0,
                  settings.reference_step > 0 ? settings.reference_step : 0.25 * vmin,
                  report.near_camera_detail,
                  {double(horizon[0]) + (double(zenith[0]) - double(horizon[0])) * (2.0 / 3.0),
                   double(horizon[1]) + (double(zenith[1]) - double(horizon[1])) * (2.0 / 3.0),
                   double(horizon[2]) + (double(zenith[2]) - double(horizon[2])) * (2.0 / 3.0)},
                  lights,
                  0.25 * vmin * vmin};

    const int w = settings.width, h = settings.height;
    Field2D image({{w, h}}, 4, Box2d{{{0, 0}}, {{double(w), double(h)}}}, {"r", "g", "b", "transmittance"});
    const Vec3d fwd = normalized(settings.camera.look_at - settings.camera.position);
    const Vec3d right = normalized(cross(fwd, settings.camera.up));
    const Vec3d up = cross(right, fwd);
    const double half_h = std::tan(0.5 * settings.camera.fov_deg * std::numbers::pi / 180);
    const double half_w = half_h * double(w) / double(h);

    const int tiles_x = (w + kTile - 1) / kTile, tiles_y = (h + kTile - 1) / kTile;
    const int tiles = tiles_x * tiles_y;
    std::vector<uint64_t> tile_samples(size_t(tiles), 0);
    std::atomic<int> done{0};
    std::atomic<bool> cancelled{false};
    run([&] {
        tbb::parallel_for(tbb::blocked_range<int>(0, tiles, 1), [&](const tbb::blocked_range<int>& r) {
            for (int ti = r.begin(); ti != r.end(); ++ti) {
                if (cancelled.load(std::memory_order_relaxed)) return;
                if (progress && progress->cancelled()) {
                    cancelled = true;
                    return;
                }
                const int x0 = (ti % tiles_x) * kTile, y0 = (ti / tiles_x) * kTile;
                uint64_t samples = 0;
                for (int y = y0; y < std::min(h, y0 + kTile); ++y)
                    for (int x = x0; x < std::min(w, x0 + kTile); ++x) {
                        const double u = (2 * (x + 0.5) / w - 1) * half_w;
                        const double v = (2 * (y + 0.5) / h - 1) * half_h;
                        const Vec3d dir = normalized(fwd + right * u + up * v);
                        const float jitter = hash_to_unit(hash_coords(settings.seed, x, y));
                        double rgb[3], trans;
                        if (lights.empty()) in.trace<false>(settings.camera.position, dir, jitter, rgb, trans, samples);
                        else in.trace<true>(settings.camera.position, dir, jitter, rgb, trans, samples);
                        const double up_t = detail::saturate(dir[2]);
                        for (int c = 0; c < 3; ++c) {
                            const double sky = double(horizon[c]) + (double(zenith[c]) - double(horizon[c])) * up_t;
                            image.at(c, x, y) = static_cast<float>(rgb[c] + trans * sky);
                        }
                        image.at(3, x, y) = static_cast<float>(trans);
                    }
                tile_samples[size_t(ti)] = samples;
                const int n = ++done;
                if (progress && progress->on_progress) {
                    ProgressEvent e;
                    e.task = fast ? "render" : "render (reference)";
                    e.done = n;
                    e.total = tiles;
                    e.fraction = double(n) / tiles;
                    progress->on_progress(e);
                }
            }
        });
    });
    if (cancelled) throw CancelledError();
    for (uint64_t s : tile_samples) report.density_samples += s;
    return {std::move(image), report};
}

} // namespace atlas::render

namespace atlas::render {

RenderSettings preview_settings(const Box3d& bounds, int width, int height) {
    if (width <= 0 || height <= 0)
        throw Error("render: image size must be at least 1x1 pixels, got " + std::to_string(width) + "x" + std::to_string(height));
    RenderSettings s;
    s.width = width;
    s.height = height;
    s.camera = framing_camera(bounds, double(width) / double(height));
    return s;
}

} // namespace atlas::render

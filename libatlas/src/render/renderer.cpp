#include "atlas/render/renderer.h"

#include "diffusion.h"
#include "light_grid.h"
#include "render_common.h"
#include "atlas/core/parallel.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>

namespace atlas::render {

std::vector<std::string> RenderReport::active_features() const {
    std::vector<std::string> f;
    if (physical) f.push_back("physical");
    if (noise_uprez) f.push_back("noise_uprez");
    if (billowy) f.push_back("billowy");
    if (near_camera_detail) f.push_back("near_camera_detail");
    if (sdf_skipping) f.push_back("sdf_skipping");
    f.push_back(light_grid ? "light_grid" : "marched_light");
    f.push_back(physical ? "beer" : "beer_powder");
    f.push_back("dual_hg");
    f.push_back("ambient");
    f.push_back(physical ? "ms_octaves" : "multiple_scattering");
    if (diffusion) f.push_back("ms_diffusion");
    if (point_lights) f.push_back("point_lights");
    if (sky_gradient) f.push_back("sky_gradient");
    return f;
}

namespace detail {

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
    if (!(s.sky_occlusion >= 0) || !std::isfinite(s.sky_occlusion)) bad("sky_occlusion must be finite and >= 0");
    if (!(s.multiple_scattering >= 0) || !std::isfinite(s.multiple_scattering)) bad("multiple_scattering must be finite and >= 0");
    if (!(s.reference_step >= 0) || !std::isfinite(s.reference_step)) bad("reference_step must be finite and >= 0 (0 = automatic)");
    if (!(s.min_transmittance >= 0 && s.min_transmittance < 1)) bad("min_transmittance must be in [0, 1)");
    if (s.threads < 0) bad("threads must be >= 0 (0 = all cores)");
    if (s.light_samples < 1 || s.light_samples > 64) bad("light_samples must be 1..64");
    if (s.ms_octaves < 0 || s.ms_octaves > 16) bad("ms_octaves must be 0..16");
    if (!(s.ms_scatter_power >= 0 && s.ms_scatter_power <= 8)) bad("ms_scatter_power must be in [0, 8]");
    if (s.ms_diffusion_sweeps < 1 || s.ms_diffusion_sweeps > 4096) bad("ms_diffusion_sweeps must be 1..4096");
    for (double v : {s.ms_energy, s.ms_extinction, s.ms_anisotropy})
        if (!(v >= 0 && v <= 1)) bad("ms_energy, ms_extinction and ms_anisotropy must be in [0, 1]");
    for (size_t i = 0; i < s.lights.size(); ++i) validate_light(s.lights[i], "lights[" + std::to_string(i) + "]");
}

} // namespace detail

namespace {

using detail::remap;

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
    // Summed density toward the sun and straight up, looked up: null in
    // reference mode and without use_light_grid (then marched).
    const detail::SunDepthMap* sun_map;
    const detail::SunDepthMap* sky_map;
    bool fast;                     // fast mode's adaptive steps (and skipping, with skip_empty_space)
    const detail::DiffusionGrid* diffusion; // null without ms_diffusion
    const RenderSettings& s;
    Vec3d sun;       // unit, toward the sun
    double base_step; // metres at the camera
    double grow;      // metres of distance per extra base step
    double light_step;
    double ref_step;
    bool near_detail;
    const detail::Sky& sky;           // the sky light reaching the cloud: its mean, or the diffusion's sky field
    const std::vector<PointLight>& lights;
    double light_core2;               // squared core radius of the inverse-square falloff

    double phase(double cos_theta) const { return detail::dual_hg(s, cos_theta); }
    // Fast mode's step at distance t: base_step, doubling every `grow` metres.
    double fast_step(double t) const { return base_step * (1 + t / grow); }

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
        if (!sun_map) {
            sun_sum = march_density(p, sun, 2 * ref_step);
            sky_sum = march_density(p, Vec3d{{0, 0, 1}}, 2 * ref_step);
            return;
        }
        // The first two samples are taken explicitly (detail near surfaces),
        // the rest of the way comes from the sun depth map.
        const double l = light_step;
        double acc = 0;
        for (int i = 0; i < 2; ++i) {
            const Vec3d q = p + sun * ((i + 0.5) * l);
            acc += cloud.density_at(q[0], q[1], q[2], 1e30) * l;
        }
        const Vec3d q = p + sun * (2 * l);
        acc += sun_map->sun(q[0], q[1], q[2]);
        sun_sum = acc;
        sky_sum = sky_map->sun(p[0], p[1], p[2]);
    }

    // Summed density (density x metres) from p toward a light `len` metres
    // away along unit `dir`, inside the volume only.
    double light_depth(const Vec3d& p, const Vec3d& dir, double len) const {
        if (!sun_map) return march_density(p, dir, 2 * ref_step, len);
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
    void point_light_radiance(const Vec3d& p, const Vec3d& view, double half_step, double out[3]) const {
        detail::point_light_radiance(s, lights, light_core2, p, view, half_step, [&](const Vec3d& q, const Vec3d& d, double len) { return light_depth(q, d, len); },
                                     out);
    }

    // Returns radiance (clouds only) and transmittance along one ray.
    // kLights: compiled with the point-light term only when the scene has lights.
    template <bool kLights>
    void trace(const Vec3d& o, const Vec3d& dir, float jitter, double rgb[3], double& trans, uint64_t& samples) const {
        rgb[0] = rgb[1] = rgb[2] = 0;
        trans = 1;
        const auto hit = clip_ray(cloud.bounds(), o, dir);
        if (!hit) return;
        const detail::SunTerms st = detail::sun_terms(s, dot(dir, sun));
        const double ext = s.extinction;
        const double min_t = s.min_transmittance;
        double t = hit->first;
        const double t_end = hit->second;
        bool first = true;
        while (t < t_end) {
            double dt = fast ? fast_step(t) : ref_step;
            if (first) dt *= 0.5 + 0.5 * jitter; // jittered start decorrelates banding
            first = false;
            if (fast && s.skip_empty_space) {
                // Sphere tracing: the SDF's empty ball, when longer than the step,
                // is crossed by walking the march's own steps without sampling
                // (each one's sample point lies in the ball, outside the cloud):
                // the march goes on exactly where it would have, the same picture.
                const Vec3d p = o + dir * t;
                const double end = t + cloud.sdf(p[0], p[1], p[2]);
                if (end - t > dt) {
                    while (t + 0.5 * std::min(dt, t_end - t) < end && t < t_end) {
                        t += std::min(dt, t_end - t);
                        dt = fast_step(t);
                    }
                    if (!(t < t_end)) break;
                }
            }
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
                    double sun_w, sky_w, diffuse_sun = -1, sky_field = -1;
                    if (diffusion) diffusion->radiances(p[0], p[1], p[2], dir * -1.0, diffuse_sun, sky_field);
                    detail::shade(s, st, ext * sun_sum, detail::saturate(v.profile), remap(v.sdf, -128.0, 0.0, 0.05, 0.25), ext * sky_sum,
                                  sun_w, sky_w, diffuse_sun);
                    // Energy-conserving step integral: (1 - exp(-sigma dt)) of the
                    // light is scattered toward the eye (albedo 1).
                    const double absorbed = -std::expm1(-sigma * dt);
                    const double w = trans * absorbed;
                    for (int c = 0; c < 3; ++c) rgb[c] += w * (sun_w * s.sun_colour[c] + sky_w * sky.light(c, sky_field));
                    if constexpr (kLights) {
                        double glow[3];
                        point_light_radiance(p, dir, 0.5 * dt, glow);
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
    detail::check_settings(settings);
    detail::CloudSampler cloud(scene);
    const bool fast = settings.mode == RenderMode::Fast;
    const Vec3d sun = detail::normalized(settings.sun_direction);
    // Lights: the given ones, then each light field's flash in order.
    std::vector<PointLight> lights = settings.lights;
    for (const LightField& f : settings.light_fields) {
        auto flash = flash_lights(f);
        lights.insert(lights.end(), flash.begin(), flash.end());
    }
    const detail::Sky sky(settings);

    RenderReport report;
    report.point_lights = !lights.empty();
    report.point_light_count = int(lights.size());
    report.sky_gradient = settings.sky_horizon.has_value();
    report.noise_uprez = cloud.has_noise();
    report.billowy = cloud.has_noise() && cloud.billowy();
    report.sdf_skipping = fast && settings.skip_empty_space;
    report.light_grid = fast && settings.use_light_grid;
    report.physical = !settings.artistic;
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
    // The diffusion term's grid (in reference mode too: its source is the
    // grid's sun transmittance), calibrated (docs/render.md) at the
    // light_grid setting capped at the volume's resolution.
    std::unique_ptr<detail::LightGrid> grid;
    std::unique_ptr<detail::DiffusionGrid> diffusion;
    // The march's light lookups: the sun and sky depth maps.
    const bool lookup = fast && settings.use_light_grid;
    std::unique_ptr<detail::SunDepthMap> sun_map, sky_map;
    with_thread_limit(settings.threads, [&] {
        if (lookup) {
            // density_at reads the SDF alone first (most of a table lies outside the cloud)
            // and the other channels only inside.
            const auto density = [&cloud](double x, double y, double z) { return cloud.density_at(x, y, z, 1e30); };
            // Columns at most 8 m apart (the pack's voxels: the up-rez's
            // detail casts shadows that fine) within a sample budget. The
            // 16 m quickstart at its own spacing stayed 6/255 from marched
            // light at the 99.9th percentile, with the sun's columns 8 m apart
            // 5/255, and with the sky's 11 m apart as well 4/255. The sky is
            // diffuse light: half the sun's budget.
            const Vec3i r = scene.modeling->resolution();
            const double voxels = double(r[0]) * double(r[1]) * double(r[2]);
            const auto across = [&](double budget) {
                return std::max(1.0, std::min({std::max({vox[0], vox[1], vox[2]}) / 8.0, 4.0, std::sqrt(budget / voxels)}));
            };
            // Where the SDF is a lower bound of the distance to any density, its balls are
            // skipped unread (exact); with the view march's switch.
            const detail::LightGrid::DensityFn distance = [&cloud](double x, double y, double z) { return cloud.sdf(x, y, z); };
            const detail::LightGrid::DensityFn* skip = settings.skip_empty_space && scene.sdf_is_lower_bound ? &distance : nullptr;
            sun_map = std::make_unique<detail::SunDepthMap>(cloud.bounds(), vox, sun, density, across(double(1 << 25)), skip);
            sky_map = std::make_unique<detail::SunDepthMap>(cloud.bounds(), vox, Vec3d{{0, 0, 1}}, density, across(double(1 << 24)), skip);
        }
        if (detail::diffusion_wanted(settings)) {
            Vec3i grid_res = settings.light_grid;
            for (int a = 0; a < 3; ++a) grid_res[a] = std::min(grid_res[a], scene.modeling->resolution()[a]);
            grid = std::make_unique<detail::LightGrid>(cloud, grid_res, sun);
            diffusion = std::make_unique<detail::DiffusionGrid>(*grid, settings.extinction, detail::phase_mean_cosine(settings), settings.ms_diffusion_sweeps,
                                                                detail::DiffusionGrid::Voxels::Thin, true, true, settings.ms_inter_cloud);
        }
    });
    report.diffusion = diffusion != nullptr;

    Integrator in{cloud,
                  sun_map.get(),
                  sky_map.get(),
                  fast,
                  diffusion.get(),
                  settings,
                  sun,
                  0.5 * vmin / settings.quality,
                  128 * vmin, // the step doubles every 128 voxels of distance
                  lookup ? 0.5 * sun_map->voxel_min() : 0.0, // the sun map's explicit near samples
                  settings.reference_step > 0 ? settings.reference_step : 0.25 * vmin,
                  report.near_camera_detail,
                  sky,
                  lights,
                  0.25 * vmin * vmin};

    const int w = settings.width, h = settings.height;
    Field2D image({{w, h}}, 4, Box2d{{{0, 0}}, {{double(w), double(h)}}}, {"r", "g", "b", "transmittance"});
    const detail::Pinhole cam(settings);
    report.density_samples =
        detail::for_each_pixel(settings, progress, fast ? "render" : "render (reference)", [&](int x, int y, float jitter, uint64_t& samples) {
            const Vec3d dir = cam.dir(x, y);
            double rgb[3], trans;
            if (lights.empty()) in.trace<false>(settings.camera.position, dir, jitter, rgb, trans, samples);
            else in.trace<true>(settings.camera.position, dir, jitter, rgb, trans, samples);
            const double up_t = detail::saturate(dir[2]);
            for (int c = 0; c < 3; ++c) image.at(c, x, y) = static_cast<float>(rgb[c] + trans * sky.at(c, up_t));
            image.at(3, x, y) = static_cast<float>(trans);
        });
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
    s.sun_direction = sun_direction(kPreviewSunAzimuthDeg, kPreviewSunElevationDeg); // the preview's sun (renderer.h)
    s.sky_occlusion = kPreviewSkyOcclusion;
    return s;
}

} // namespace atlas::render

namespace atlas::render {

Field3D sample_density(const CloudScene& scene, Vec3i res) {
    for (int a = 0; a < 3; ++a)
        if (res[a] < 1 || res[a] > 2048) throw Error("render: sample_density resolution must be 1..2048 per axis");
    detail::CloudSampler cloud(scene);
    const Box3d b = cloud.bounds();
    Field3D out(res, 1, b, {"density"});
    const Vec3d v = out.voxel_size();
    parallel_for_index(res[2], [&](int z) {
        for (int y = 0; y < res[1]; ++y)
            for (int x = 0; x < res[0]; ++x)
                out.at(0, x, y, z) =
                    cloud.density_at(b.min[0] + (x + 0.5) * v[0], b.min[1] + (y + 0.5) * v[1], b.min[2] + (z + 0.5) * v[2], 1e30);
    });
    return out;
}

CloudScene density_scene(const Field3D& density) {
    if (density.channels() < 1) throw Error("render: density_scene needs a field with a density channel");
    // The sampler's density is (profile x scale)^(0.3 + 0.3 min(1, scale)^4):
    // with scale S >= 1 the power is 0.6, so profile = D^(1/0.6) / S gives D.
    float dmax = 0;
    for (float d : density.channel(0)) {
        if (!(d >= 0) || !std::isfinite(d)) throw Error("render: density_scene needs finite densities >= 0");
        dmax = std::max(dmax, d);
    }
    const double S = std::max(1.0, std::pow(double(dmax), 1.0 / 0.6));
    auto m = std::make_shared<Field3D>(density.resolution(), 3, density.bounds(),
                                       std::vector<std::string>{"dimensional_profile", "detail_type", "density_scale"});
    auto sdf = std::make_shared<Field3D>(density.resolution(), 1, density.bounds(), std::vector<std::string>{"sdf"});
    const Vec3d vox = density.voxel_size();
    const float inside = -static_cast<float>(std::min({vox[0], vox[1], vox[2]}));
    auto d = density.channel(0);
    auto p = m->channel(0), t = m->channel(1), sc = m->channel(2), sd = sdf->channel(0);
    for (size_t i = 0; i < d.size(); ++i) {
        p[i] = static_cast<float>(std::pow(double(d[i]), 1.0 / 0.6) / S);
        t[i] = 0;
        sc[i] = static_cast<float>(S);
        sd[i] = inside;
    }
    CloudScene s;
    s.modeling = m;
    s.sdf = sdf;
    validate_scene(s);
    return s;
}

} // namespace atlas::render

// The 2.5D cloudscape renderer's entry points (atlas/render/layer.h; formulas
// in docs/render.md, "2.5D mode"): validation, the shell's geometry, the
// render (the march per pixel is layer_march.cpp, the density it reads
// layer_model.h, the physical mode's diffusion patch layer_diffusion.cpp) and
// the queries and cameras over a scene.
#include "atlas/render/layer.h"

#include "layer_diffusion.h"
#include "layer_march.h"
#include "layer_model.h"
#include "render_common.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
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

// The density model: layer_model.h; the march: layer_march.h.
using namespace layer_detail;

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

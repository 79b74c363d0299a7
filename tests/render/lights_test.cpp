// Point lights, probability-field lights and the sky gradient: the old path
// is untouched without them, lights add nothing without a medium, radiance
// stays finite, non-negative and falls with distance.
#include "atlas/core/error.h"
#include "atlas/core/hash.h"
#include "atlas/render/renderer.h"
#include "render_scenes.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

using namespace atlas;
using namespace atlas::render;
using namespace atlas::render::testing;

namespace {

RenderSettings golden_settings(RenderMode mode, bool close) {
    RenderSettings s;
    s.width = 37;
    s.height = 29;
    s.light_grid = {{16, 16, 16}};
    s.mode = mode;
    s.reference_step = 1;
    s.camera.position = close ? Vec3d{{60, 20, 55}} : Vec3d{{50, -150, 60}};
    s.camera.look_at = {{50, 50, 50}};
    return s;
}

std::string image_hash(const Field2D& img) {
    Hasher h;
    for (int c = 0; c < 4; ++c) h.add_floats(img.channel(c));
    return h.finish().hex();
}

} // namespace

TEST(RenderLights, NoLightsKeepsThePreLightsBytes) {
    // Hashes of these renders made by the renderer before point lights and
    // the sky gradient existed (commit 099fa8e, same scene code): without
    // lights and with the uniform sky the new code must give the same bytes.
    // The fast-mode pair was re-recorded when the fast march began jittering
    // its first step at the volume's entry instead of after the first SDF
    // skip (skips then walk the march's own steps: on and off, same bytes).
    auto scene = sphere_scene(24, 100, 30, 0.6);
    scene.noise = make_noise(16);
    scene.noise_tile = 40;
    const char* expected[2][2] = {{"8f4d3367ada95a1dae27dbf57bc69d23", "eb42a9de2837eb6eaf2f89daa73a3826"},
                                  {"431b034e9ae4cd1f4bbb42ca4e001cd5", "e0bf01b00d781dfed97d5065e125e0e0"}};
    for (int mode = 0; mode < 2; ++mode)
        for (int close = 0; close < 2; ++close) {
            auto r = render_clouds(scene, golden_settings(mode ? RenderMode::Reference : RenderMode::Fast, close != 0));
            EXPECT_EQ(image_hash(r.image), expected[mode][close]) << "mode " << mode << " close " << close;
        }
}

namespace {

constexpr double kBox = 200;

// Density exactly 1 everywhere in [0, 200]^3 (profile 1, scale 1, no noise).
CloudScene homogeneous_box() {
    return make_scene(16, kBox, [](Vec3d p) { return -std::min({p[0], p[1], p[2], kBox - p[0], kBox - p[1], kBox - p[2]}) - 1; },
                      [](Vec3d, double) { return 1.0; });
}

// Horizontal centre ray along +y at x = 100, z = 100 (odd image: the centre
// pixel is exactly that ray); sun and sky off so only point lights shine.
RenderSettings lights_only(RenderMode mode) {
    RenderSettings s;
    s.width = 5;
    s.height = 5;
    s.mode = mode;
    s.camera.position = {{100, -50, 100}};
    s.camera.look_at = {{100, 100, 100}};
    s.sun_colour = {{0, 0, 0}};
    s.sky_colour = {{0, 0, 0}};
    s.light_grid = {{16, 16, 16}};
    s.min_transmittance = 0;
    return s;
}

void expect_sane(const Field2D& img, const std::string& what) {
    for (int c = 0; c < 4; ++c)
        for (float v : img.channel(c)) {
            ASSERT_TRUE(std::isfinite(v)) << what;
            ASSERT_GE(v, 0.0f) << what;
            if (c == 3) {
                ASSERT_LE(v, 1.0f) << what;
            }
        }
}

} // namespace

TEST(RenderLights, LightInEmptyVolumeAddsNothing) {
    auto empty = make_scene(8, 100, [](Vec3d) { return 10.0; }, [](Vec3d, double) { return 1.0; });
    for (RenderMode mode : {RenderMode::Fast, RenderMode::Reference}) {
        RenderSettings s;
        s.width = 12;
        s.height = 9;
        s.mode = mode;
        s.camera.position = {{50, -100, 50}};
        s.camera.look_at = {{50, 50, 50}};
        s.lights.push_back({{{50, 50, 50}}, {{1, 0.5f, 0.2f}}, 1e6, 0});
        auto r = render_clouds(empty, s);
        EXPECT_TRUE(r.report.point_lights);
        EXPECT_EQ(r.report.point_light_count, 1);
        for (int y = 0; y < s.height; ++y)
            for (int x = 0; x < s.width; ++x) {
                for (int c = 0; c < 3; ++c) ASSERT_EQ(r.image.at(c, x, y), s.sky_colour[c]);
                ASSERT_EQ(r.image.at(3, x, y), 1.0f);
            }
    }
}

TEST(RenderLights, OpticallyThinGlowMatchesClosedForm) {
    // Independent reference: with a tiny extinction sigma the medium is
    // optically thin (view and light transmittance ~ 1) and with g = 0 the
    // phase is 1, so the centre ray collects
    //   L = sigma * I * integral_{-100}^{100} ds / (s^2 + H^2)
    //     = sigma * I * 2 atan(100 / H) / H,   H^2 = h^2 + core^2,
    // core = half a voxel (200 m / 16 / 2). Stated tolerance: 2e-3 relative
    // (reference), 1e-2 (fast: longer midpoint steps).
    const double sigma = 1e-6, intensity = 1e6, core = 0.5 * kBox / 16;
    for (double h : {20.0, 50.0})
        for (RenderMode mode : {RenderMode::Fast, RenderMode::Reference}) {
            RenderSettings s = lights_only(mode);
            s.extinction = sigma;
            s.hg_forward = s.hg_back = 0;
            s.lights.push_back({{{100 + h, 100, 100}}, {{1, 1, 1}}, intensity, 0});
            auto r = render_clouds(homogeneous_box(), s);
            const double H = std::sqrt(h * h + core * core);
            const double expected = sigma * intensity * 2 * std::atan(100 / H) / H;
            const double tol = mode == RenderMode::Reference ? 2e-3 : 1e-2;
            EXPECT_NEAR(r.image.at(0, 2, 2), expected, tol * expected) << "h " << h << " mode " << int(mode);
        }
}

TEST(RenderLights, GlowInHomogeneousBoxFallsWithDistance) {
    for (RenderMode mode : {RenderMode::Fast, RenderMode::Reference}) {
        double previous = std::numeric_limits<double>::infinity();
        for (double h : {5.0, 15.0, 30.0, 60.0, 90.0}) {
            RenderSettings s = lights_only(mode);
            s.extinction = 0.01;
            s.lights.push_back({{{100 + h, 120, 100}}, {{1, 0.4f, 0.2f}}, 1e5, 0});
            auto r = render_clouds(homogeneous_box(), s);
            expect_sane(r.image, "distance " + std::to_string(h));
            const double centre = r.image.at(0, 2, 2);
            EXPECT_GT(centre, 0.0);
            EXPECT_LT(centre, previous) << "light " << h << " m from the view ray, mode " << int(mode);
            previous = centre;
        }
    }
}

TEST(RenderLights, RadianceIsLinearInIntensityAndZeroIntensityIsNoLight) {
    auto scene = sphere_scene(16, 100, 35, 0.5);
    scene.noise = make_noise(8);
    scene.noise_tile = 50;
    for (RenderMode mode : {RenderMode::Fast, RenderMode::Reference}) {
        RenderSettings s = lights_only(mode);
        s.width = 16;
        s.height = 12;
        s.camera.position = {{50, -80, 60}};
        s.camera.look_at = {{50, 50, 50}};
        const Vec3d centre_voxel = scene.modeling->voxel_center(8, 8, 8); // a light exactly at a voxel centre
        auto dark = render_clouds(scene, s);
        s.lights.push_back({centre_voxel, {{1, 1, 1}}, 0, 0});
        auto zero = render_clouds(scene, s);
        EXPECT_TRUE(same_bytes(dark.image, zero.image)) << "intensity 0 must add exactly nothing";
        s.lights[0].intensity = 1e3;
        auto one = render_clouds(scene, s);
        s.lights[0].intensity = 2e3;
        auto two = render_clouds(scene, s);
        s.lights[0].intensity = 1e6;
        auto huge = render_clouds(scene, s);
        expect_sane(huge.image, "intensity 1e6");
        double lit = 0;
        for (int y = 0; y < s.height; ++y)
            for (int x = 0; x < s.width; ++x) {
                const double a = one.image.at(0, x, y), b = two.image.at(0, x, y);
                lit += a;
                EXPECT_NEAR(b, 2 * a, 1e-5 * (1 + b)) << x << "," << y;
                EXPECT_EQ(one.image.at(3, x, y), dark.image.at(3, x, y)) << "lights do not change transmittance";
            }
        EXPECT_GT(lit, 0.0);
    }
}

TEST(RenderLights, RadiusCutsTheLightOff) {
    RenderSettings s = lights_only(RenderMode::Fast);
    s.extinction = 0.01;
    auto dark = render_clouds(homogeneous_box(), s);
    // 400 m outside the box with a 300 m reach: no sample is within range.
    s.lights.push_back({{{100, 100, 600}}, {{1, 1, 1}}, 1e9, 300});
    EXPECT_TRUE(same_bytes(dark.image, render_clouds(homogeneous_box(), s).image));
    s.lights[0].radius = 0; // unlimited: the same light now reaches the box
    EXPECT_GT(render_clouds(homogeneous_box(), s).image.at(0, 2, 2), 0.0f);
}

TEST(RenderLights, ExtremeLightsStayFinite) {
    auto scene = sphere_scene(16, 100, 35, 0.5);
    scene.noise = make_noise(8);
    scene.noise_tile = 50;
    for (RenderMode mode : {RenderMode::Fast, RenderMode::Reference}) {
        RenderSettings s = lights_only(mode);
        s.width = 12;
        s.height = 8;
        s.camera.position = {{50, 50, 50}}; // camera inside the cloud, on a light
        s.camera.look_at = {{80, 60, 40}};
        s.extinction = 100;
        s.lights.push_back({{{50, 50, 50}}, {{1e6f, 1e6f, 1e6f}}, 1e6, 0});
        s.lights.push_back({scene.modeling->voxel_center(3, 4, 5), {{1, 1, 1}}, 1e6, 1e-3});
        s.lights.push_back({{{1e7, -1e7, 1e7}}, {{1, 1, 1}}, 1e6, 0});
        expect_sane(render_clouds(scene, s).image, "extinction 100");
        s.extinction = 1e-9;
        expect_sane(render_clouds(scene, s).image, "extinction 1e-9");
    }
}

TEST(RenderLights, SameBytesWithOneAndTwoThreads) {
    auto scene = sphere_scene(24, 100, 30, 0.6);
    scene.noise = make_noise(16);
    scene.noise_tile = 40;
    auto field = std::make_shared<Field3D>(Vec3i{{5, 5, 5}}, 1, scene.modeling->bounds());
    for (float& v : field->channel(0)) v = 0.5f;
    for (RenderMode mode : {RenderMode::Fast, RenderMode::Reference}) {
        RenderSettings s = golden_settings(mode, true);
        s.reference_step = 3; // 5 marched light rays per sample: keep the test quick
        s.lights.push_back({{{50, 50, 50}}, {{1, 0.3f, 0.2f}}, 2e4, 80});
        s.light_fields.push_back({field, 0, {{0.7f, 0.8f, 1}}, 1e4, 60, 9, 2, 4});
        s.sky_horizon = Vec3f{{0.8f, 0.7f, 0.6f}};
        s.threads = 1;
        auto a = render_clouds(scene, s);
        s.threads = 2;
        auto b = render_clouds(scene, s);
        EXPECT_EQ(a.report.point_light_count, 5);
        EXPECT_TRUE(same_bytes(a.image, b.image)) << "mode " << int(mode);
    }
}

TEST(RenderLights, BadLightsAreClearErrors) {
    auto scene = sphere_scene(8, 100, 30);
    auto expect_error = [&](PointLight l, const std::string& needle) {
        RenderSettings s = lights_only(RenderMode::Fast);
        s.lights = {PointLight{}, l};
        try {
            render_clouds(scene, s);
            ADD_FAILURE() << "expected an error naming " << needle;
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
        }
    };
    const double nan = std::numeric_limits<double>::quiet_NaN();
    expect_error({{{nan, 0, 0}}, {{1, 1, 1}}, 1, 0}, "lights[1] position");
    expect_error({{{0, 0, 0}}, {{-1, 1, 1}}, 1, 0}, "lights[1] colour");
    expect_error({{{0, 0, 0}}, {{1, 1, 1}}, std::numeric_limits<double>::infinity(), 0}, "lights[1] intensity");
    expect_error({{{0, 0, 0}}, {{1, 1, 1}}, 1, -2}, "lights[1] radius");
    RenderSettings s = lights_only(RenderMode::Fast);
    s.light_samples = 0;
    EXPECT_THROW(render_clouds(scene, s), Error);
}

TEST(RenderLights, ReportListsLightsAndSky) {
    auto scene = sphere_scene(8, 100, 30);
    RenderSettings s = lights_only(RenderMode::Fast);
    auto has = [](const RenderReport& r, const std::string& f) {
        auto v = r.active_features();
        return std::find(v.begin(), v.end(), f) != v.end();
    };
    auto plain = render_clouds(scene, s).report;
    EXPECT_FALSE(has(plain, "point_lights"));
    EXPECT_FALSE(has(plain, "sky_gradient"));
    s.lights.push_back({{{50, 50, 50}}, {{1, 1, 1}}, 1, 0});
    s.sky_horizon = Vec3f{{1, 1, 1}};
    auto lit = render_clouds(scene, s).report;
    EXPECT_TRUE(has(lit, "point_lights"));
    EXPECT_TRUE(has(lit, "sky_gradient"));
}

// ---- probability-field (flash) lights ----

namespace {
Field3DPtr flash_field(const std::vector<std::pair<Vec3i, float>>& hot) {
    auto f = std::make_shared<Field3D>(Vec3i{{8, 6, 4}}, 1, Box3d{{{-40, 0, 100}}, {{40, 60, 140}}});
    for (const auto& [v, w] : hot) f->at(0, v[0], v[1], v[2]) = w;
    return f;
}
} // namespace

TEST(RenderFlashLights, DeterministicPerSeedAndFlash) {
    LightField f;
    f.probability = flash_field({{{{1, 2, 3}}, 1.0f}, {{{6, 0, 1}}, 2.0f}, {{{3, 5, 0}}, 0.5f}});
    f.count = 5;
    auto a = flash_lights(f), b = flash_lights(f);
    ASSERT_EQ(a.size(), 5u);
    for (size_t i = 0; i < a.size(); ++i) EXPECT_EQ(a[i].position, b[i].position);
    f.flash = 1;
    auto c = flash_lights(f);
    bool moved = false;
    for (size_t i = 0; i < a.size(); ++i) moved = moved || !(a[i].position == c[i].position);
    EXPECT_TRUE(moved) << "a new flash index picks new positions";
}

TEST(RenderFlashLights, PositionsOnlyWhereProbabilityIsPositive) {
    LightField f;
    const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
    f.probability = flash_field({{{{1, 2, 3}}, 1.0f}, {{{6, 0, 1}}, 3.0f}, {{{0, 0, 0}}, -5.0f}, {{{7, 5, 3}}, nan}, {{{2, 2, 2}}, inf}});
    f.count = 2000;
    f.intensity = 7;
    f.colour = {{1, 0, 0}};
    auto lights = flash_lights(f);
    ASSERT_EQ(lights.size(), 2000u);
    int in_a = 0, in_b = 0;
    const Vec3d vox = f.probability->voxel_size();
    for (const auto& l : lights) {
        EXPECT_EQ(l.intensity, 7);
        const int x = int(std::floor((l.position[0] + 40) / vox[0])), y = int(std::floor(l.position[1] / vox[1])),
                  z = int(std::floor((l.position[2] - 100) / vox[2]));
        if (x == 1 && y == 2 && z == 3) ++in_a;
        else if (x == 6 && y == 0 && z == 1) ++in_b;
        else ADD_FAILURE() << "light in voxel " << x << "," << y << "," << z << " which has no positive probability";
    }
    // Proportional to the weights 1 : 3 (binomial sd ~ 19 of 500).
    EXPECT_NEAR(in_a, 500, 80);
    EXPECT_NEAR(in_b, 1500, 80);
}

TEST(RenderFlashLights, EmptyFieldGivesNoLightAndBadFieldsThrow) {
    LightField f;
    f.probability = flash_field({});
    f.count = 10;
    EXPECT_TRUE(flash_lights(f).empty());
    // A render with an all-zero field runs the no-light path: same bytes.
    auto scene = sphere_scene(8, 100, 30);
    RenderSettings s = lights_only(RenderMode::Fast);
    s.sky_colour = {{0.3f, 0.4f, 0.5f}};
    auto plain = render_clouds(scene, s);
    s.light_fields.push_back(f);
    auto r = render_clouds(scene, s);
    EXPECT_FALSE(r.report.point_lights);
    EXPECT_TRUE(same_bytes(plain.image, r.image));
    LightField bad = f;
    bad.probability = nullptr;
    EXPECT_THROW(flash_lights(bad), Error);
    bad = f;
    bad.channel = 1;
    EXPECT_THROW(flash_lights(bad), Error);
    bad = f;
    bad.count = -1;
    EXPECT_THROW(flash_lights(bad), Error);
    bad = f;
    bad.intensity = -1;
    EXPECT_THROW(flash_lights(bad), Error);
}

TEST(RenderFlashLights, AFlashInsideTheCloudLightsIt) {
    auto scene = sphere_scene(16, 100, 35);
    auto field = std::make_shared<Field3D>(Vec3i{{4, 4, 4}}, 1, scene.modeling->bounds());
    field->at(0, 1, 2, 1) = 1; // inside the sphere
    RenderSettings s = lights_only(RenderMode::Fast);
    s.width = 16;
    s.height = 12;
    s.camera.position = {{50, -80, 50}};
    s.camera.look_at = {{50, 50, 50}};
    auto dark = render_clouds(scene, s);
    s.light_fields.push_back({field, 0, {{1, 0.8f, 0.6f}}, 1e4, 0, 3, 0, 3});
    auto lit = render_clouds(scene, s);
    EXPECT_EQ(lit.report.point_light_count, 3);
    double gain = 0;
    for (int y = 0; y < s.height; ++y)
        for (int x = 0; x < s.width; ++x) gain += lit.image.at(0, x, y) - dark.image.at(0, x, y);
    EXPECT_GT(gain, 0.0);
}

// ---- sky gradient ----

TEST(RenderSky, EmptyVolumeShowsTheGradientExactly) {
    auto empty = make_scene(8, 100, [](Vec3d) { return 10.0; }, [](Vec3d, double) { return 1.0; });
    const Vec3f zenith{{0.1f, 0.3f, 0.9f}}, horizon{{0.9f, 0.8f, 0.6f}};
    for (RenderMode mode : {RenderMode::Fast, RenderMode::Reference}) {
        RenderSettings s;
        s.width = 20;
        s.height = 31;
        s.mode = mode;
        s.camera.position = {{50, 50, 50}};
        s.camera.look_at = {{50, 150, 90}};
        s.camera.fov_deg = 120; // rows from below the horizon to high up
        s.sky_colour = zenith;
        s.sky_horizon = horizon;
        auto r = render_clouds(empty, s);
        // Independent pinhole: view elevation of each pixel's ray.
        const Vec3d fwd = (s.camera.look_at - s.camera.position) / length(s.camera.look_at - s.camera.position);
        const Vec3d right = cross(fwd, s.camera.up) / length(cross(fwd, s.camera.up));
        const Vec3d up = cross(right, fwd);
        const double th = std::tan(s.camera.fov_deg * M_PI / 360), tw = th * s.width / s.height;
        int below = 0;
        for (int y = 0; y < s.height; ++y)
            for (int x = 0; x < s.width; ++x) {
                Vec3d d = fwd + right * ((2 * (x + 0.5) / s.width - 1) * tw) + up * ((2 * (y + 0.5) / s.height - 1) * th);
                d = d / length(d);
                const double t = std::clamp(d[2], 0.0, 1.0);
                if (d[2] < 0) ++below;
                for (int c = 0; c < 3; ++c) ASSERT_NEAR(r.image.at(c, x, y), horizon[c] + (zenith[c] - horizon[c]) * t, 1e-6) << x << "," << y;
                ASSERT_EQ(r.image.at(3, x, y), 1.0f);
            }
        EXPECT_GT(below, 0) << "the test should see below the horizon too";
    }
}

TEST(RenderSky, AmbientUsesTheHemisphereMeanOfTheGradient) {
    // Sun off: a cloud lit by the gradient equals the same cloud lit by a
    // uniform sky of horizon + 2/3 (zenith - horizon) (cos-weighted mean over
    // the upper hemisphere), apart from the background seen through it.
    auto scene = sphere_scene(16, 100, 35);
    const Vec3f zenith{{0.1f, 0.3f, 0.9f}}, horizon{{0.9f, 0.8f, 0.6f}};
    RenderSettings s;
    s.width = 9;
    s.height = 9;
    s.sun_colour = {{0, 0, 0}};
    s.camera.position = {{50, -100, 50}};
    s.camera.look_at = {{50, 50, 50}};
    s.camera.fov_deg = 10;
    s.sky_colour = zenith;
    s.sky_horizon = horizon;
    auto grad = render_clouds(scene, s);
    RenderSettings u = s;
    u.sky_horizon.reset();
    for (int c = 0; c < 3; ++c) u.sky_colour[c] = horizon[c] + (zenith[c] - horizon[c]) * (2.0f / 3.0f);
    auto uni = render_clouds(scene, u);
    for (int c = 0; c < 3; ++c) {
        const double tr = grad.image.at(3, 4, 4);
        ASSERT_LT(tr, 0.9);
        // Remove the background term T * sky(dir); the centre ray is horizontal (sky = horizon).
        const double cloud_grad = grad.image.at(c, 4, 4) - tr * horizon[c];
        const double cloud_uni = uni.image.at(c, 4, 4) - tr * u.sky_colour[c];
        EXPECT_NEAR(cloud_grad, cloud_uni, 1e-5);
    }
}

// Golden values from an independent path: a constant-density slab whose
// centre-pixel radiance has a closed form (the renderer's own output is
// never stored). Also the sweep and image writers.
#include "atlas/core/error.h"
#include "atlas/io/exr.h"
#include "atlas/io/image.h"
#include "atlas/render/image_out.h"
#include "atlas/render/sweep.h"
#include "render_scenes.h"

#include <gtest/gtest.h>

#include <filesystem>

#include <unistd.h>

using namespace atlas;
using namespace atlas::render;
using namespace atlas::render::testing;

namespace {

constexpr double kProfile = 0.75;

CloudScene constant_box() {
    return make_scene(16, 200, [](Vec3d p) { return -std::min({p[0], p[1], p[2], 200 - p[0], 200 - p[1], 200 - p[2]}) - 1; },
                      [](Vec3d, double) { return kProfile; });
}

// The camera looks horizontally along +y at height z through the box; the
// centre pixel of an odd-sized image is exactly the forward ray.
RenderSettings centre_ray(double z) {
    RenderSettings s;
    s.width = 5;
    s.height = 5;
    s.camera.position = {{100, -50, z}};
    s.camera.look_at = {{100, 100, z}};
    s.extinction = 0.01;
    s.min_transmittance = 0;
    s.light_grid = {{16, 16, 16}};
    return s;
}

double hg(double c, double g) { return (1 - g * g) / std::pow(1 + g * g - 2 * g * c, 1.5); }

} // namespace

TEST(RenderGolden, AmbientOnlySlabMatchesClosedForm) {
    // Sun off: radiance = amb * sky * (1 - e^{-sigma L}) + sky * e^{-sigma L}
    // with density d = 0.75^0.6 (sharpening power at scale 1), sigma = ext d,
    // amb = sqrt(1 - 0.75) * e^{-ext d (200 - z)} (summed density to the top).
    // Stated tolerance: 1e-3 relative.
    const double d = std::pow(kProfile, 0.6);
    for (double z : {60.0, 100.0, 150.0})
        for (RenderMode mode : {RenderMode::Fast, RenderMode::Reference}) {
            RenderSettings s = centre_ray(z);
            s.mode = mode;
            s.sun_colour = {{0, 0, 0}};
            auto r = render_clouds(constant_box(), s);
            const double sigma = s.extinction * d, L = 200;
            const double amb = std::sqrt(1 - kProfile) * std::exp(-s.extinction * d * (200 - z));
            for (int c = 0; c < 3; ++c) {
                const double sky = s.sky_colour[c];
                const double expect = amb * sky * (1 - std::exp(-sigma * L)) + sky * std::exp(-sigma * L);
                EXPECT_NEAR(r.image.at(c, 2, 2), expect, 1e-3 * expect) << "z " << z << " mode " << int(mode);
            }
            EXPECT_NEAR(r.image.at(3, 2, 2), std::exp(-sigma * L), 1e-5);
        }
}

TEST(RenderGolden, OverheadSunSlabMatchesClosedForm) {
    // Sun straight up, view horizontal: cos theta = 0, powder mix 1/2,
    // tau = ext d (200 - z) along the whole ray, multiple scattering
    // dp e^{-0.25 tau}. Sky off. Stated tolerance: 2e-3 relative.
    const double d = std::pow(kProfile, 0.6);
    for (double z : {80.0, 140.0})
        for (RenderMode mode : {RenderMode::Fast, RenderMode::Reference}) {
            RenderSettings s = centre_ray(z);
            s.mode = mode;
            s.sky_colour = {{0, 0, 0}};
            s.sun_direction = {{0, 0, 1}};
            auto r = render_clouds(constant_box(), s);
            const double tau = s.extinction * d * (200 - z);
            const double phase = s.hg_forward_weight * hg(0, s.hg_forward) + (1 - s.hg_forward_weight) * hg(0, s.hg_back);
            const double powder = 1 - std::exp(-2 * tau);
            const double direct = std::exp(-tau) * (powder + (1 - powder) * 0.5) * phase;
            const double ms = kProfile * std::exp(-0.25 * tau);
            const double sigma = s.extinction * d;
            for (int c = 0; c < 3; ++c) {
                const double expect = (direct + s.multiple_scattering * ms) * s.sun_colour[c] * (1 - std::exp(-sigma * 200));
                EXPECT_NEAR(r.image.at(c, 2, 2), expect, 2e-3 * expect) << "z " << z << " mode " << int(mode);
            }
        }
}

TEST(RenderSweep, ReportsErrorAndTimePerQuality) {
    auto scene = sphere_scene(24, 100, 30, 0.4);
    scene.noise = make_noise(16);
    scene.noise_tile = 50;
    RenderSettings s;
    s.width = 32;
    s.height = 24;
    s.camera = framing_camera(scene.modeling->bounds(), 32.0 / 24.0);
    s.light_grid = {{24, 24, 24}};
    s.reference_step = 1;
    auto sweep = quality_sweep(scene, s, {0.5, 2});
    ASSERT_EQ(sweep.rows.size(), 2u);
    for (const auto& r : sweep.rows) {
        EXPECT_TRUE(std::isfinite(r.rmse));
        EXPECT_GE(r.rmse, 0);
        EXPECT_GT(r.seconds, 0);
    }
    // More quality is closer to the reference in transmittance.
    EXPECT_LE(sweep.rows[1].transmittance_rmse, sweep.rows[0].transmittance_rmse + 1e-6);
    EXPECT_THROW(quality_sweep(scene, s, {}), Error);
    // RMSE of an image with itself is 0, and positive against a different one.
    EXPECT_EQ(image_rmse(sweep.reference, sweep.reference, 0, 4), 0.0);
}

TEST(RenderOutput, PngAndExrRoundTrip) {
    auto scene = sphere_scene(16, 100, 30);
    RenderSettings s;
    s.width = 20;
    s.height = 12;
    s.camera = framing_camera(scene.modeling->bounds(), 20.0 / 12.0);
    s.light_grid = {{16, 16, 16}};
    auto r = render_clouds(scene, s);
    const auto dir = std::filesystem::temp_directory_path() / ("atlas_render_test_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    io::write_image(tone_map(r.image), dir / "p.png");
    io::ExrOptions exr;
    exr.channel_meaning = kLinearImageMeaning;
    io::write_exr(r.image, dir / "p.exr", exr);
    Field2D png = io::read_image(dir / "p.png");
    EXPECT_EQ(png.width(), 20);
    EXPECT_EQ(png.channels(), 3);
    Field2D tm = tone_map(r.image);
    for (int y = 0; y < 12; ++y)
        for (int x = 0; x < 20; ++x) EXPECT_NEAR(png.at(0, x, y), tm.at(0, x, y), 0.5 / 255 + 1e-6);
    Value v = io::read_exr(dir / "p.exr");
    const auto& back = *std::get<Field2DPtr>(v);
    ASSERT_EQ(back.channels(), 4);
    for (int c = 0; c < 4; ++c) {
        int bc = back.find_channel(r.image.channel_name(c));
        ASSERT_GE(bc, 0);
        for (size_t i = 0; i < back.voxel_count(); ++i) EXPECT_EQ(back.channel(bc)[i], r.image.channel(c)[i]);
    }
    EXPECT_THROW(tone_map(r.image, 0), Error);
    std::filesystem::remove_all(dir);
}

// Golden values from an independent path: a constant-density slab whose
// centre-pixel radiance has a closed form (the renderer's own output is
// never stored). Also the sweep and image writers.
#include "atlas/core/error.h"
#include "atlas/io/animation.h"
#include "atlas/io/exr.h"
#include "atlas/io/image.h"
#include "atlas/render/image_out.h"
#include "atlas/render/sweep.h"
#include "render_scenes.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <limits>
#include <string>

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
    // amb = sqrt(1 - 0.75) * e^{-k ext d (200 - z)} (summed density to the top,
    // k = sky_occlusion: 1 the library's default, 0.1 the preview's, 0 none).
    // Stated tolerance: 1e-3 relative.
    const double d = std::pow(kProfile, 0.6);
    for (double k : {1.0, kPreviewSkyOcclusion, 0.0}) {
        for (double z : {60.0, 100.0, 150.0})
            for (RenderMode mode : {RenderMode::Fast, RenderMode::Reference}) {
                RenderSettings s = centre_ray(z);
                s.mode = mode;
                s.sun_colour = {{0, 0, 0}};
                s.sky_occlusion = k;
                auto r = render_clouds(constant_box(), s);
                const double sigma = s.extinction * d, L = 200;
                const double amb = std::sqrt(1 - kProfile) * std::exp(-k * s.extinction * d * (200 - z));
                for (int c = 0; c < 3; ++c) {
                    const double sky = s.sky_colour[c];
                    const double expect = amb * sky * (1 - std::exp(-sigma * L)) + sky * std::exp(-sigma * L);
                    EXPECT_NEAR(r.image.at(c, 2, 2), expect, 1e-3 * expect) << "k " << k << " z " << z << " mode " << int(mode);
                }
                EXPECT_NEAR(r.image.at(3, 2, 2), std::exp(-sigma * L), 1e-5);
            }
    }
    RenderSettings bad = centre_ray(100);
    for (double k : {-0.1, std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
        bad.sky_occlusion = k;
        EXPECT_THROW(render_clouds(constant_box(), bad), Error) << k;
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

namespace {
// A frame whose every pixel says which frame and where: r = frame / 10, g = x / w, b = y / h.
Field2D labelled_frame(int frame, int w, int h) {
    Field2D f({{w, h}}, 3, Box2d{{{0, 0}}, {{double(w), double(h)}}}, {"r", "g", "b"});
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            f.at(0, x, y) = float(frame) / 10.0f;
            f.at(1, x, y) = float(x) / float(w);
            f.at(2, x, y) = float(y) / float(h);
        }
    return f;
}
} // namespace

TEST(RenderOutput, ContactSheetPutsFrameZeroTopLeftAndScalesDownToFit) {
    // Five 8x4 frames: three columns, two rows, 2 pixels of black between.
    ContactSheet s(5, 8, 4, 0, 1920, 2);
    EXPECT_EQ(s.columns(), 3);
    EXPECT_EQ(s.scale(), 1);
    for (int i = 0; i < 5; ++i) s.add(i, labelled_frame(i, 8, 4));
    const Field2D& sh = s.sheet();
    ASSERT_EQ(sh.width(), 3 * 8 + 2 * 2);
    ASSERT_EQ(sh.height(), 2 * 4 + 2);
    // The field's y = 0 is the bottom: frame 0's tile is the top rows.
    for (int i = 0; i < 5; ++i) {
        const int x0 = (i % 3) * 10, y0 = sh.height() - (i / 3 + 1) * 4 - (i / 3) * 2;
        for (int y = 0; y < 4; ++y)
            for (int x = 0; x < 8; ++x) {
                EXPECT_FLOAT_EQ(sh.at(0, x0 + x, y0 + y), float(i) / 10.0f) << "frame " << i;
                EXPECT_FLOAT_EQ(sh.at(1, x0 + x, y0 + y), float(x) / 8.0f);
                EXPECT_FLOAT_EQ(sh.at(2, x0 + x, y0 + y), float(y) / 4.0f);
            }
    }
    EXPECT_EQ(sh.at(0, 8, sh.height() - 1), 0.0f); // the gap
    EXPECT_EQ(sh.at(0, 25, 0), 0.0f);              // the sixth, empty tile
    // Twenty-four 960x540 frames fit 1920 pixels in five columns at a third of their size (box filter).
    ContactSheet big(24, 960, 540);
    EXPECT_EQ(big.columns(), 5);
    EXPECT_EQ(big.scale(), 3);
    EXPECT_LE(big.sheet().width(), 1920);
    ContactSheet tiny(1, 4, 4, 0, 1, 0); // a sheet narrower than a pixel per tile keeps one pixel
    EXPECT_EQ(tiny.sheet().width(), 1);
    tiny.add(0, labelled_frame(3, 4, 4));
    EXPECT_NEAR(tiny.sheet().at(0, 0, 0), 0.3f, 1e-6f); // the mean of a constant
    EXPECT_THROW(ContactSheet(0, 8, 4), Error);
    EXPECT_THROW(s.add(5, labelled_frame(0, 8, 4)), Error);
    EXPECT_THROW(s.add(0, labelled_frame(0, 8, 5)), Error);
}

TEST(RenderOutput, AnimationWriterRefusesBadOptionsAndFrames) {
    io::AnimationOptions o;
    o.fps = 0;
    EXPECT_THROW(io::AnimationWriter(8, 4, o), Error);
    o.fps = 12;
    o.quality = 102;
    EXPECT_THROW(io::AnimationWriter(8, 4, o), Error);
    EXPECT_THROW(io::AnimationWriter(0, 4), Error);
    io::AnimationWriter w(8, 4);
    EXPECT_THROW(w.add(labelled_frame(0, 9, 4)), Error);
    Field2D nan = labelled_frame(0, 8, 4);
    nan.at(1, 2, 3) = std::numeric_limits<float>::quiet_NaN();
    try {
        w.add(nan);
        ADD_FAILURE() << "a NaN frame was accepted";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("NaN at pixel (2, 3)"), std::string::npos) << e.what();
    }
    const auto dir = std::filesystem::temp_directory_path() / ("atlas_anim_test_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    EXPECT_THROW(w.write(dir / "none.webp"), Error); // no frames
    w.add(labelled_frame(0, 8, 4));
    EXPECT_EQ(w.frames(), 1);
    EXPECT_THROW(w.write(dir / "a.gif"), Error);
    EXPECT_FALSE(std::filesystem::exists(dir / "a.gif"));
    w.write(dir / "a.webp");
    EXPECT_GT(std::filesystem::file_size(dir / "a.webp"), 0u);
    EXPECT_THROW(w.add(labelled_frame(1, 8, 4)), Error); // spent
    std::filesystem::remove_all(dir);
}

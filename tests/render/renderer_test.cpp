// Renderer properties: empty volume, Beer's law, SDF skipping, extremes,
// bad settings, thread-count determinism.
#include "atlas/core/error.h"
#include "atlas/render/renderer.h"
#include "render_scenes.h"

#include <gtest/gtest.h>

#include <algorithm>

using namespace atlas;
using namespace atlas::render;
using namespace atlas::render::testing;

namespace {

RenderSettings small_settings(int w = 24, int h = 16) {
    RenderSettings s;
    s.width = w;
    s.height = h;
    s.camera.position = {{50, -150, 60}};
    s.camera.look_at = {{50, 50, 50}};
    s.light_grid = {{16, 16, 16}};
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

// Independent slab clip for the analytic Beer test.
double chord(const Box3d& b, Vec3d o, Vec3d d) {
    double t0 = 0, t1 = 1e300;
    for (int a = 0; a < 3; ++a) {
        if (d[a] == 0) continue;
        double ta = (b.min[a] - o[a]) / d[a], tb = (b.max[a] - o[a]) / d[a];
        t0 = std::max(t0, std::min(ta, tb));
        t1 = std::min(t1, std::max(ta, tb));
    }
    return t1 > t0 ? t1 - t0 : 0;
}

} // namespace

TEST(Render, EmptyVolumeIsPureSky) {
    auto scene = make_scene(8, 100, [](Vec3d) { return 10.0; }, [](Vec3d, double) { return 1.0; });
    for (RenderMode mode : {RenderMode::Fast, RenderMode::Reference}) {
        RenderSettings s = small_settings();
        s.mode = mode;
        s.camera.position = {{50, 50, 50}}; // inside the bounds too
        s.camera.look_at = {{60, 80, 40}};
        auto r = render_clouds(scene, s);
        for (int y = 0; y < s.height; ++y)
            for (int x = 0; x < s.width; ++x) {
                for (int c = 0; c < 3; ++c) ASSERT_EQ(r.image.at(c, x, y), s.sky_colour[c]);
                ASSERT_EQ(r.image.at(3, x, y), 1.0f);
            }
    }
}

TEST(Render, HomogeneousBoxFollowsBeersLaw) {
    // SDF < 0 everywhere, profile 1, scale 1, no noise: density exactly 1.
    auto scene = make_scene(8, 100, [](Vec3d p) { return -std::min({p[0], p[1], p[2], 100 - p[0], 100 - p[1], 100 - p[2]}) - 1; },
                            [](Vec3d, double) { return 1.0; });
    const Box3d b = scene.modeling->bounds();
    for (RenderMode mode : {RenderMode::Fast, RenderMode::Reference}) {
        RenderSettings s = small_settings(15, 11);
        s.mode = mode;
        s.extinction = 0.02;
        s.min_transmittance = 0;
        s.camera.position = {{130, -90, 140}};
        s.camera.look_at = {{50, 50, 50}};
        auto r = render_clouds(scene, s);
        const Vec3d fwd = (s.camera.look_at - s.camera.position) / length(s.camera.look_at - s.camera.position);
        const Vec3d right = cross(fwd, s.camera.up) / length(cross(fwd, s.camera.up));
        const Vec3d up = cross(right, fwd);
        const double hh = std::tan(0.5 * s.camera.fov_deg * 3.14159265358979323846 / 180), hw = hh * s.width / s.height;
        int hits = 0;
        for (int y = 0; y < s.height; ++y)
            for (int x = 0; x < s.width; ++x) {
                Vec3d d = fwd + right * ((2 * (x + 0.5) / s.width - 1) * hw) + up * ((2 * (y + 0.5) / s.height - 1) * hh);
                d = d / length(d);
                const double L = chord(b, s.camera.position, d);
                hits += L > 0;
                EXPECT_NEAR(r.image.at(3, x, y), std::exp(-s.extinction * L), 1e-5) << x << "," << y;
            }
        EXPECT_GT(hits, s.width * s.height / 3);
    }
}

TEST(Render, SdfSkippingNeverMissesDensity) {
    // Thin shell and a small sphere. SDF skipping walks the march's own
    // steps over the empty ball, so fast mode with and without it must give
    // the same bytes. The adaptive steps against fixed small steps: per pixel
    // |T_fast - T_fixed| <= 0.08 (measured up to 0.063: one jittered 1-spp
    // step's error at a thin shell), RMSE <= 0.02, and no pixel the
    // reference sees as cloudy (T < 0.95) comes out clear (T > 0.999).
    std::vector<CloudScene> scenes;
    scenes.push_back(sphere_scene(32, 100, 15));
    scenes.push_back(make_scene(32, 100, [](Vec3d p) { return std::fabs(length(p - Vec3d{{50, 50, 50}}) - 35) - 3; },
                                [](Vec3d, double d) { return std::clamp(-d / 3, 0.0, 1.0); }));
    scenes.push_back(sphere_scene(32, 100, 30));
    scenes.back().noise = make_noise(16);
    scenes.back().noise_tile = 60;
    for (size_t i = 0; i < scenes.size(); ++i) {
        RenderSettings s = small_settings(40, 30);
        s.extinction = 0.08;
        s.min_transmittance = 0;
        auto fast = render_clouds(scenes[i], s);
        EXPECT_TRUE(fast.report.sdf_skipping);
        {
            RenderSettings no_skip = s;
            no_skip.skip_empty_space = false;
            const auto plain = render_clouds(scenes[i], no_skip);
            EXPECT_FALSE(plain.report.sdf_skipping);
            EXPECT_TRUE(std::equal(fast.image.channel(0).begin(), fast.image.channel(0).end(), plain.image.channel(0).begin()) &&
                        std::equal(fast.image.channel(3).begin(), fast.image.channel(3).end(), plain.image.channel(3).begin()))
                << "SDF skipping changed the picture, scene " << i;
        }
        s.mode = RenderMode::Reference;
        s.reference_step = 0.5;
        auto ref = render_clouds(scenes[i], s);
        double sum = 0;
        int cloudy = 0;
        for (int y = 0; y < s.height; ++y)
            for (int x = 0; x < s.width; ++x) {
                const double tf = fast.image.at(3, x, y), tr = ref.image.at(3, x, y);
                EXPECT_NEAR(tf, tr, 0.08) << "scene " << i << " pixel " << x << "," << y;
                if (tr < 0.95) {
                    ++cloudy;
                    EXPECT_LT(tf, 0.999) << "missed density, scene " << i << " pixel " << x << "," << y;
                }
                sum += (tf - tr) * (tf - tr);
            }
        EXPECT_LE(std::sqrt(sum / (s.width * s.height)), 0.02) << "scene " << i;
        EXPECT_GT(cloudy, 10) << "scene " << i;
        EXPECT_LT(fast.report.density_samples, ref.report.density_samples);
    }
}

TEST(Render, ExtremesStayFiniteAndNonNegative) {
    auto base = sphere_scene(16, 100, 30, 0.5);
    base.noise = make_noise(8);
    base.noise_tile = 50;
    struct Case {
        std::string name;
        std::function<void(RenderSettings&, CloudScene&)> edit;
    };
    std::vector<Case> cases = {
        {"sun at horizon", [](RenderSettings& s, CloudScene&) { s.sun_direction = sun_direction(30, 0); }},
        {"sun below horizon", [](RenderSettings& s, CloudScene&) { s.sun_direction = sun_direction(30, -20); }},
        {"sun straight down", [](RenderSettings& s, CloudScene&) { s.sun_direction = {{0, 0, -1}}; }},
        {"sun behind camera", [](RenderSettings& s, CloudScene&) { s.sun_direction = s.camera.position - s.camera.look_at; }},
        {"sun toward camera", [](RenderSettings& s, CloudScene&) { s.sun_direction = s.camera.look_at - s.camera.position; }},
        {"camera inside cloud", [](RenderSettings& s, CloudScene&) { s.camera.position = {{50, 45, 50}}; }},
        {"density scale 0", [](RenderSettings&, CloudScene& c) { c = sphere_scene(16, 100, 30, 0.5, 0.0); }},
        {"density scale 100", [](RenderSettings&, CloudScene& c) { c = sphere_scene(16, 100, 30, 0.5, 100.0); }},
        {"extinction 100/m", [](RenderSettings& s, CloudScene&) { s.extinction = 100; }},
        {"extinction 1e-9/m", [](RenderSettings& s, CloudScene&) { s.extinction = 1e-9; }},
        {"huge sun", [](RenderSettings& s, CloudScene&) { s.sun_colour = {{1e6f, 1e6f, 1e6f}}; }},
        {"tiny fov", [](RenderSettings& s, CloudScene&) { s.camera.fov_deg = 1e-3; }},
        {"wide fov", [](RenderSettings& s, CloudScene&) { s.camera.fov_deg = 179; }},
        {"far camera", [](RenderSettings& s, CloudScene&) { s.camera.position = {{1e7, -1e7, 5e6}}; }},
        {"NaN in fields", [](RenderSettings&, CloudScene& c) {
             auto m = std::make_shared<Field3D>(*c.modeling);
             m->at(0, 8, 8, 8) = std::nanf("");
             m->at(2, 7, 8, 8) = std::numeric_limits<float>::infinity();
             c.modeling = m;
         }},
    };
    for (const auto& k : cases)
        for (RenderMode mode : {RenderMode::Fast, RenderMode::Reference}) {
            RenderSettings s = small_settings(12, 8);
            s.mode = mode;
            s.reference_step = 2;
            CloudScene scene = base;
            k.edit(s, scene);
            auto r = render_clouds(scene, s);
            expect_sane(r.image, k.name);
        }
}

TEST(Render, BadSettingsAreClearErrors) {
    auto scene = sphere_scene(8, 100, 30);
    auto expect_error = [&](const std::function<void(RenderSettings&)>& edit, const std::string& needle) {
        RenderSettings s = small_settings();
        edit(s);
        try {
            render_clouds(scene, s);
            ADD_FAILURE() << "no error for " << needle;
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
        }
    };
    expect_error([](RenderSettings& s) { s.width = 0; }, "image size");
    expect_error([](RenderSettings& s) { s.height = 0; s.width = 0; }, "image size");
    expect_error([](RenderSettings& s) { s.height = -3; }, "image size");
    expect_error([](RenderSettings& s) { s.camera.fov_deg = 0; }, "fov");
    expect_error([](RenderSettings& s) { s.camera.fov_deg = 180; }, "fov");
    expect_error([](RenderSettings& s) { s.camera.look_at = s.camera.position; }, "look_at");
    expect_error([](RenderSettings& s) { s.camera.position[0] = std::nan(""); }, "camera.position");
    expect_error([](RenderSettings& s) { s.sun_direction = {{0, 0, 0}}; }, "sun_direction");
    expect_error([](RenderSettings& s) { s.quality = 0; }, "quality");
    expect_error([](RenderSettings& s) { s.extinction = -1; }, "extinction");
    expect_error([](RenderSettings& s) { s.camera.up = s.camera.look_at - s.camera.position; }, "camera.up");
    CloudScene missing;
    EXPECT_THROW(render_clouds(missing, small_settings()), Error);
}

TEST(Render, SameBytesWithOneAndTwoThreads) {
    auto scene = sphere_scene(24, 100, 30, 0.6);
    scene.noise = make_noise(16);
    scene.noise_tile = 40;
    for (RenderMode mode : {RenderMode::Fast, RenderMode::Reference}) {
        RenderSettings s = small_settings(37, 29); // not a multiple of the tile size
        s.mode = mode;
        s.reference_step = 1;
        s.camera.position = {{60, 20, 55}}; // close: near-camera detail on
        s.threads = 1;
        auto a = render_clouds(scene, s);
        s.threads = 2;
        auto b = render_clouds(scene, s);
        EXPECT_TRUE(a.report.near_camera_detail);
        EXPECT_TRUE(atlas::render::testing::same_bytes(a.image, b.image));
        EXPECT_EQ(a.report.density_samples, b.report.density_samples);
    }
}

TEST(Render, ReportListsOnlyWhatRan) {
    auto plain = sphere_scene(8, 100, 30, 0.0);
    RenderSettings s = small_settings(8, 8);
    auto r = render_clouds(plain, s);
    EXPECT_FALSE(r.report.noise_uprez);
    EXPECT_FALSE(r.report.billowy);
    EXPECT_FALSE(r.report.point_lights);
    EXPECT_TRUE(r.report.light_grid);
    auto wispy = plain;
    wispy.noise = make_noise(8);
    EXPECT_FALSE(render_clouds(wispy, s).report.billowy); // detail type all zero: no billowy branch
    auto billowy = sphere_scene(8, 100, 30, 0.7);
    billowy.noise = make_noise(8);
    auto rb = render_clouds(billowy, s);
    EXPECT_TRUE(rb.report.billowy);
    EXPECT_TRUE(rb.report.noise_uprez);
    s.mode = RenderMode::Reference;
    auto rr = render_clouds(billowy, s);
    EXPECT_FALSE(rr.report.light_grid);
    EXPECT_FALSE(rr.report.sdf_skipping);
}

// A plain density grid (one float grid "density", what vdb_render reads)
// through scene_from_fields: the sampled density is density_scene's (itself checked
// against the grid above), and the empty-space SDF never claims more room
// than there is: at random points its interpolated value stays under the
// brute-force distance to the nearest non-zero voxel's cell. Its SDF is kept
// per 2^3 block and renders the bytes of the SDF broadcast to every voxel.
#include "atlas/io/readers.h"
#include "atlas/io/vdb.h"

#include <filesystem>
#include <random>

TEST(RenderLoadScene, DensityGridGetsTheSameDensityAndASafeSdf) {
    const Vec3i res{{48, 40, 24}};
    Field3D d(res, 1, Box3d{{{-100, 50, 0}}, {{284, 370, 192}}}, {"density"});
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(0, 1);
    // Two blobs and a few stray voxels.
    for (int z = 0; z < res[2]; ++z)
        for (int y = 0; y < res[1]; ++y)
            for (int x = 0; x < res[0]; ++x) {
                const double a = std::hypot(x - 6.0, y - 5.0, z - 4.0), b = std::hypot(x - 17.0, y - 13.0, z - 7.0);
                double v = std::max(0.0, 1 - a / 4) + 0.5 * std::max(0.0, 1 - b / 3);
                if (u(rng) < 0.0003) v = u(rng);
                d.at(0, x, y, z) = static_cast<float>(v);
            }
    const auto path = std::filesystem::temp_directory_path() / "atlas_load_scene_density.vdb";
    io::write_vdb(d, path);
    const CloudScene s = scene_from_fields({{io::as_field3d(io::read_field_file(path)), path.string()}});
    std::filesystem::remove(path);
    const CloudScene ref = density_scene(d);
    // The profile alone is stored; detail type and density scale are uniform.
    EXPECT_EQ(s.modeling->channels(), 1);
    ASSERT_TRUE(s.uniform_detail_type && s.uniform_density_scale);
    EXPECT_EQ(*s.uniform_detail_type, 0.0f);
    EXPECT_EQ(*s.uniform_density_scale, ref.modeling->channel(2)[0]);
    const Field3D a = sample_density(s, res), b = sample_density(ref, res);
    for (size_t i = 0; i < a.voxel_count(); ++i) ASSERT_NEAR(a.channel(0)[i], b.channel(0)[i], 1e-6f) << i;
    // SDF bound, brute force over the non-zero voxels. The SDF is stored once per 2^3
    // block (CloudScene::sdf_block); the renderer reads every voxel as its block's value.
    ASSERT_EQ(s.sdf_block, 2);
    ASSERT_EQ(s.sdf->resolution(), (Vec3i{{24, 20, 12}}));
    Field3D sdf(res, 1, d.bounds(), {"sdf"});
    for (int z = 0; z < res[2]; ++z)
        for (int y = 0; y < res[1]; ++y)
            for (int x = 0; x < res[0]; ++x) sdf.at(0, x, y, z) = s.sdf->at(0, x / 2, y / 2, z / 2);
    const int c = 0;
    {
        // The same scene with that broadcast SDF renders the same bytes; a block SDF of
        // the wrong size is refused.
        CloudScene broadcast = s;
        broadcast.sdf = std::make_shared<const Field3D>(sdf);
        broadcast.sdf_block = 1;
        RenderSettings st = preview_settings(d.bounds(), 40, 30);
        st.light_grid = {{12, 12, 12}};
        const auto blocks = render_clouds(s, st), voxels = render_clouds(broadcast, st);
        for (int ch = 0; ch < 4; ++ch)
            for (size_t i = 0; i < blocks.image.channel(ch).size(); ++i)
                ASSERT_EQ(blocks.image.channel(ch)[i], voxels.image.channel(ch)[i]) << ch << " " << i;
        // Its SDF bounds the density from below (checked at random points below), so the
        // light tables skip by it: the picture is the one without any skipping.
        EXPECT_TRUE(s.sdf_is_lower_bound);
        RenderSettings plain = st;
        plain.skip_empty_space = false;
        const auto unskipped = render_clouds(s, plain);
        EXPECT_TRUE(blocks.report.sdf_skipping);
        EXPECT_FALSE(unskipped.report.sdf_skipping);
        for (int ch = 0; ch < 4; ++ch)
            for (size_t i = 0; i < blocks.image.channel(ch).size(); ++i)
                ASSERT_EQ(blocks.image.channel(ch)[i], unskipped.image.channel(ch)[i]) << ch << " " << i;
        CloudScene wrong = broadcast;
        wrong.sdf_block = 2;
        EXPECT_THROW(validate_scene(wrong), Error);
        wrong.sdf_block = 0;
        EXPECT_THROW(validate_scene(wrong), Error);
        wrong.sdf_block = 3; // not a power of two
        EXPECT_THROW(validate_scene(wrong), Error);
    }
    const Vec3d vox = d.voxel_size();
    const double diag = std::sqrt(vox[0] * vox[0] + vox[1] * vox[1] + vox[2] * vox[2]);
    std::vector<Vec3d> occupied;
    for (int z = 0; z < res[2]; ++z)
        for (int y = 0; y < res[1]; ++y)
            for (int x = 0; x < res[0]; ++x)
                if (d.at(0, x, y, z) > 0) occupied.push_back(d.voxel_center(x, y, z));
    int skipping = 0;
    for (int k = 0; k < 4000; ++k) {
        const Box3d bb = d.bounds();
        Vec3d p;
        for (int ax = 0; ax < 3; ++ax) p[ax] = bb.min[ax] + u(rng) * (bb.max[ax] - bb.min[ax]);
        double nearest = 1e30;
        for (const auto& o : occupied) nearest = std::min(nearest, length(p - o));
        // Non-zero density lies within one cell diagonal of a non-zero voxel's centre.
        const double room = nearest - diag;
        const float v = sdf.sample_world(c, p, WrapMode::Clamp);
        if (v > 0) ++skipping;
        ASSERT_LE(v, std::max(room, 0.0)) << p[0] << " " << p[1] << " " << p[2];
        // Wherever density_scene's profile is non-zero the point is inside.
        if (ref.modeling->sample_world(0, p, WrapMode::Clamp) > 0) {
            ASSERT_LT(v, 0.0f);
        }
    }
    EXPECT_GT(skipping, 400); // the SDF does let the march skip
}

// Uniform modeling channels (CloudScene::uniform_detail_type / _density_scale,
// as scene_from_fields makes for a density grid) render the very bytes of the same
// values stored in every voxel, with and without noise; a different uniform
// scale (negative control) changes the picture, and a profile-only field
// without uniform values is refused.
TEST(RenderScene, UniformChannelsRenderLikeStoredOnes) {
    for (bool noise : {false, true}) {
        CloudScene stored = sphere_scene(24, 240, 80, 0.0, 2.5);
        {
            // One corner voxel far outside the sphere (never read: its cells
            // are outside) differs, so the stored channels are interpolated,
            // not found uniform by the sampler's own scan.
            auto m = std::make_shared<Field3D>(*stored.modeling);
            m->at(1, 0, 0, 0) = 1e-3f;
            m->at(2, 0, 0, 0) = 2.0f;
            stored.modeling = m;
        }
        if (noise) {
            stored.noise = make_noise(16);
            stored.noise_tile = 96;
        }
        auto profile = std::make_shared<Field3D>(stored.modeling->resolution(), 1, stored.modeling->bounds(),
                                                 std::vector<std::string>{"dimensional_profile"});
        const auto src = stored.modeling->channel(0);
        std::copy(src.begin(), src.end(), profile->channel(0).begin());
        CloudScene uniform = stored;
        uniform.modeling = profile;
        uniform.uniform_detail_type = 0.0f;
        uniform.uniform_density_scale = 2.5f;
        RenderSettings s = preview_settings(stored.modeling->bounds(), 40, 30);
        s.light_grid = {{12, 12, 12}};
        const auto a = render_clouds(stored, s), b = render_clouds(uniform, s);
        for (int c = 0; c < 4; ++c)
            for (size_t i = 0; i < a.image.channel(c).size(); ++i) ASSERT_EQ(a.image.channel(c)[i], b.image.channel(c)[i]) << c << " " << i;
        EXPECT_EQ(a.report.density_samples, b.report.density_samples);
        CloudScene other = uniform;
        other.uniform_density_scale = 0.5f * *uniform.uniform_density_scale;
        const auto o = render_clouds(other, s);
        double diff = 0;
        for (size_t i = 0; i < a.image.channel(0).size(); ++i) diff += std::fabs(a.image.channel(0)[i] - o.image.channel(0)[i]);
        EXPECT_GT(diff, 1e-3);
        CloudScene bare = uniform;
        bare.uniform_density_scale.reset();
        EXPECT_THROW(validate_scene(bare), Error);
    }
}

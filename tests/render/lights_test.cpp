// Point lights, probability-field lights and the sky gradient: the old path
// is untouched without them, lights add nothing without a medium, radiance
// stays finite, non-negative and falls with distance.
#include "atlas/core/error.h"
#include "atlas/core/hash.h"
#include "atlas/render/renderer.h"
#include "render_scenes.h"

#include <gtest/gtest.h>

#include <cstring>

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
    auto scene = sphere_scene(24, 100, 30, 0.6);
    scene.noise = make_noise(16);
    scene.noise_tile = 40;
    const char* expected[2][2] = {{"92b990da4de4c4d409e44d36172afdc3", "92674cc9006762767b37ebd72c557872"},
                                  {"431b034e9ae4cd1f4bbb42ca4e001cd5", "e0bf01b00d781dfed97d5065e125e0e0"}};
    for (int mode = 0; mode < 2; ++mode)
        for (int close = 0; close < 2; ++close) {
            auto r = render_clouds(scene, golden_settings(mode ? RenderMode::Reference : RenderMode::Fast, close != 0));
            EXPECT_EQ(image_hash(r.image), expected[mode][close]) << "mode " << mode << " close " << close;
        }
}

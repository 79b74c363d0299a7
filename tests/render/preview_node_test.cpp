// The render/preview node: cooks through the registry like the evaluator
// does, on a small NVDF set, and agrees with the library call.
#include "atlas/graph/node.h"
#include "atlas/render/image_out.h"
#include "atlas/render/renderer.h"
#include "render_scenes.h"

#include <gtest/gtest.h>

using namespace atlas;

namespace {

Field3DPtr nvdf_set() {
    auto sc = render::testing::sphere_scene(16, 100, 30, 0.5);
    auto set = std::make_shared<Field3D>(sc.modeling->resolution(), 4, sc.modeling->bounds(),
                                         std::vector<std::string>{"dimensional_profile", "detail_type", "density_scale", "sdf"});
    for (int c = 0; c < 3; ++c) std::copy(sc.modeling->channel(c).begin(), sc.modeling->channel(c).end(), set->channel(c).begin());
    std::copy(sc.sdf->channel(0).begin(), sc.sdf->channel(0).end(), set->channel(3).begin());
    return set;
}

std::map<std::string, Value> cook(const std::map<std::string, ParamValue>& params, std::map<std::string, Value> inputs) {
    NodeRegistry reg = builtin_nodes();
    const NodeType* t = reg.find("render/preview");
    EXPECT_NE(t, nullptr);
    // Resolved parameters, as the evaluator passes them: defaults, then the given values.
    std::map<std::string, ParamValue> values;
    for (const auto& d : t->decl.params()) values[d.name] = d.default_value;
    for (const auto& [k, v] : params) values[k] = v;
    NodeParams p(&t->decl, values, ".");
    MemoryBudget budget;
    ProgressSink progress;
    CookContext ctx("preview", "render/preview", t->decl, p, std::move(inputs), budget, progress);
    t->cook(ctx);
    return ctx.outputs();
}

} // namespace

TEST(RenderPreviewNode, MatchesLibraryRender) {
    auto set = nvdf_set();
    auto out = cook({{"size", std::vector<double>{20, 12}}}, {{"nvdf", set}});
    auto image = std::get<Field2DPtr>(out.at("image"));
    auto preview = std::get<Field2DPtr>(out.at("preview"));
    ASSERT_EQ(image->width(), 20);
    ASSERT_EQ(image->height(), 12);
    ASSERT_EQ(image->channels(), 4);
    ASSERT_EQ(preview->channels(), 3);
    // Same as the library with the node's defaults (auto camera, sun 60/35).
    auto scene = render::scene_from_nvdf_set(set);
    auto s = render::preview_settings(set->bounds(), 20, 12);
    s.sun_direction = render::sun_direction(60, 35);
    auto r = render::render_clouds(scene, s);
    EXPECT_TRUE(r.image == *image);
    EXPECT_TRUE(render::tone_map(r.image, 1.5) == *preview);
    // Some pixels see cloud.
    float min_t = 1;
    for (float v : image->channel(3)) min_t = std::min(min_t, v);
    EXPECT_LT(min_t, 0.5f);
}

TEST(RenderPreviewNode, NeedsAnNvdfSet) {
    EXPECT_THROW(cook({}, {}), Error);
    auto set = nvdf_set();
    auto bad = std::make_shared<Field3D>(set->resolution(), 2, set->bounds());
    EXPECT_THROW(cook({}, {{"nvdf", Field3DPtr(bad)}}), Error);
}

TEST(RenderPreviewNode, LightsSkyAndFlashParamsReachTheRenderer) {
    auto set = nvdf_set();
    const std::vector<double> size{20, 12};
    const std::vector<double> horizon{0.9, 0.8, 0.6};
    auto out = cook({{"size", size}, {"lights", std::string("50 50 50 1 0.5 0.2 2e4; 10 20 30 0 0 1 1e3 40")}, {"sky_horizon", horizon}},
                    {{"nvdf", set}});
    auto image = std::get<Field2DPtr>(out.at("image"));
    // The same through the library.
    auto scene = render::scene_from_nvdf_set(set);
    auto s = render::preview_settings(set->bounds(), 20, 12);
    s.sun_direction = render::sun_direction(60, 35);
    s.sky_horizon = Vec3f{{0.9f, 0.8f, 0.6f}};
    s.lights = {{{{50, 50, 50}}, {{1, 0.5f, 0.2f}}, 2e4, 0}, {{{10, 20, 30}}, {{0, 0, 1}}, 1e3, 40}};
    auto r = render::render_clouds(scene, s);
    EXPECT_TRUE(r.report.point_lights);
    EXPECT_TRUE(r.report.sky_gradient);
    EXPECT_TRUE(r.image == *image);
    // A flash field with one hot voxel inside the cloud changes the picture.
    auto field = std::make_shared<Field3D>(Vec3i{{4, 4, 4}}, 1, set->bounds());
    field->at(0, 2, 2, 2) = 1;
    auto flash = std::get<Field2DPtr>(cook({{"size", size}, {"flash_count", int64_t(2)}}, {{"nvdf", set}, {"flash_probability", Field3DPtr(field)}}).at("image"));
    auto plain = std::get<Field2DPtr>(cook({{"size", size}}, {{"nvdf", set}}).at("image"));
    EXPECT_FALSE(*flash == *plain);
    EXPECT_THROW(cook({{"lights", std::string("1 2 3")}}, {{"nvdf", set}}), Error);
}

// Issue 42: proxy cooks (CookOptions::proxy) and the one preview entry of a session
// (atlas/preview/graph_preview.h) that the CLI, Python, the C API and Blender call.
#include "atlas/core/error.h"
#include "atlas/graph/evaluator.h"
#include "atlas/preview/graph_preview.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <variant>

using namespace atlas;

namespace {

// A small voxel cloud: spheres grown into billows, splatted, smoothed (sigma in
// voxels), its SDF and NVDF set; every grid 64 x 64 x 32 over 1 km x 1 km x 500 m.
const char* kCloud = R"(atlas: 1
nodes:
  shape:
    type: volume/billows
    params: {spheres: 500 500 200 150; 650 520 230 110, levels: 1, children: 8, base_height: 90, seed: 2}
  density:
    type: volume/metaballs
    inputs: {points: shape}
    params: {resolution: [64, 64, 32], bounds_max: [1000, 1000, 500], kernel: sphere, blend: max}
  soft:
    type: volume/filter
    inputs: {in: density}
    params: {op: smooth, sigma: 2}
  sdf:
    type: volume/sdf
    inputs: {in: soft}
    params: {iso: 0.5}
  nvdf:
    type: volume/nvdf
    inputs: {sdf: sdf}
    params: {depth: 30}
outputs:
  - {node: nvdf, port: vdb_set, file: cloud.vdb}
)";

Session cloud_session() {
    Session s(builtin_nodes());
    s.load_text(kCloud, "cloud.yaml", ".");
    return s;
}

CookOptions values(int proxy, int jobs = 0) {
    CookOptions o;
    o.write_outputs = false;
    o.proxy = proxy;
    o.jobs = jobs;
    return o;
}

// A 64 x 36 orbit view of kCloud, drawn without the up-rez noise.
render::PreviewOptions orbit_picture(preview::GraphPreviewOptions& how) {
    how.noise = "none";
    render::PreviewOptions po;
    preview::set_preview_options(po, {{"size", "64,36"}, {"view", "orbit"}});
    return po;
}

render::PreviewOptions small_picture() {
    render::PreviewOptions po;
    preview::set_preview_options(po, {{"size", "48,27"}});
    return po;
}

} // namespace

TEST(Proxy, EveryWorldGridHasAQuarterOfItsCellsOverTheSameBounds) {
    Session s = cloud_session();
    const auto full = std::get<Field3DPtr>(s.get("density", "out", values(1)));
    const auto proxy = std::get<Field3DPtr>(s.get("density", "out", values(4)));
    EXPECT_EQ(full->resolution(), (Vec3i{{64, 64, 32}}));
    EXPECT_EQ(proxy->resolution(), (Vec3i{{16, 16, 8}}));
    EXPECT_EQ(proxy->bounds().min, full->bounds().min);
    EXPECT_EQ(proxy->bounds().max, full->bounds().max);
    // A node downstream follows its input's grid; the NVDF set is a quarter too.
    const auto set = std::get<Field3DPtr>(s.get("nvdf", "vdb_set", values(4)));
    EXPECT_EQ(set->resolution(), (Vec3i{{16, 16, 8}}));
    // Cell counts round up: proxy 3 of 64 is 22, of 32 is 11.
    EXPECT_EQ(std::get<Field3DPtr>(s.get("density", "out", values(3)))->resolution(), (Vec3i{{22, 22, 11}}));
}

TEST(Proxy, ResultsAreCachedApartAndNodesWithoutGridsAreShared) {
    Session s = cloud_session();
    s.cook(values(1));
    const CookResult r = s.cook(values(4));
    // The points (no grid) are the full cook's; every grid node cooks at the proxy size.
    EXPECT_EQ(r.nodes.at("shape").status, "cached");
    EXPECT_EQ(r.nodes.at("density").status, "cooked");
    EXPECT_EQ(r.nodes.at("nvdf").status, "cooked");
    EXPECT_EQ(r.proxy, 4);
    // Back to full: all from memory, nothing re-cooked; and the proxy's again.
    const CookResult again = s.cook(values(1));
    EXPECT_EQ(again.nodes.at("nvdf").status, "cached");
    EXPECT_EQ(s.cook(values(4)).nodes.at("nvdf").status, "cached");
}

TEST(Proxy, NeverWritesOutputsAndRefusesABadFactor) {
    Session s = cloud_session();
    CookOptions o = values(4);
    o.write_outputs = true;
    o.out_dir = ::testing::TempDir();
    try {
        s.cook(o);
        FAIL() << "a proxy cook wrote outputs";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("never written as final outputs"), std::string::npos) << e.what();
    }
    EXPECT_THROW(s.cook(values(0)), Error);
    EXPECT_THROW(s.cook(values(65)), Error);
}

TEST(GraphPreview, OneEntryForASessionAndAnEditCooksOnlyWhatChanged) {
    Session s = cloud_session();
    preview::GraphPreviewOptions how;
    how.noise = "none";
    how.proxy = 2;
    const preview::GraphPreview first = preview::prepare_graph_preview(s, small_picture(), how, "cloud.yaml");
    ASSERT_TRUE(first.voxel);
    EXPECT_FALSE(first.layer);
    EXPECT_EQ(first.job.voxel->modeling->resolution(), (Vec3i{{32, 32, 16}}));
    ASSERT_FALSE(first.log.empty());
    EXPECT_NE(first.log.front().find("at proxy 2"), std::string::npos) << first.log.front();
    // An edit downstream of the splat: the density comes from the session's memory
    // (and the shape is not needed again); three nodes cook.
    s.set_text("soft", "sigma", "1");
    const preview::GraphPreview second = preview::prepare_graph_preview(s, small_picture(), how, "cloud.yaml");
    EXPECT_NE(second.log.front().find("graph: cooked 3, cached 1 nodes"), std::string::npos) << second.log.front();
    const render::PreviewFrame a = render::render_preview(first.job);
    const render::PreviewFrame b = render::render_preview(second.job);
    EXPECT_EQ(a.image.width(), 48);
    EXPECT_EQ(a.image.height(), 27);
    EXPECT_FALSE(a.image == b.image) << "the edit changed nothing on screen";
}

TEST(GraphPreview, TheSamePictureWhateverTheThreadCount) {
    preview::GraphPreviewOptions how;
    how.noise = "none";
    how.proxy = 2;
    Session one = cloud_session(), two = cloud_session();
    how.jobs = 1;
    const render::PreviewFrame a = preview::preview_session(one, small_picture(), how);
    how.jobs = 2;
    const render::PreviewFrame b = preview::preview_session(two, small_picture(), how);
    EXPECT_TRUE(a.image == b.image);
}

TEST(GraphPreview, BadOptionsNameTheOptionAndWhatItTakes) {
    render::PreviewOptions po;
    try {
        preview::set_preview_options(po, {{"sizes", "4,4"}});
        FAIL();
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("preview option 'sizes' does not exist"), std::string::npos) << e.what();
    }
    try {
        preview::set_preview_options(po, {{"view", "sideways"}});
        FAIL();
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("preview option 'view' expects"), std::string::npos) << e.what();
    }
    // The CLI's spelling and a host's comma list both read.
    preview::set_preview_options(po, {{"size", "64x32"}});
    EXPECT_EQ(po.size, (Vec2i{{64, 32}}));
    preview::set_preview_options(po, {{"size", "80,40"}});
    EXPECT_EQ(po.size, (Vec2i{{80, 40}}));
    Session s = cloud_session();
    preview::GraphPreviewOptions how;
    how.mode = "layer";
    try {
        preview::prepare_graph_preview(s, small_picture(), how, "cloud.yaml");
        FAIL();
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("cloud.yaml: mode layer, but the graph writes no NDF set"), std::string::npos) << e.what();
    }
}

TEST(GraphPreview, PixelSizeMarchesFewerRaysForTheSamePicture) {
    preview::GraphPreviewOptions how;
    render::PreviewOptions po = orbit_picture(how);
    Session s = cloud_session();
    const render::PreviewFrame full = preview::preview_session(s, po, how);
    preview::set_preview_options(po, {{"pixel_size", "2"}});
    const render::PreviewFrame coarse = preview::preview_session(s, po, how);
    ASSERT_EQ(coarse.image.width(), 64);
    ASSERT_EQ(coarse.image.height(), 36);
    ASSERT_TRUE(full.voxel_report && coarse.voxel_report);
    // A quarter of the rays, the same cloud where it is: transmittance within a few percent on average.
    double diff = 0, cloud = 0;
    for (int y = 0; y < 36; ++y)
        for (int x = 0; x < 64; ++x) {
            diff += std::abs(full.image.at(3, x, y) - coarse.image.at(3, x, y));
            cloud += 1 - full.image.at(3, x, y);
        }
    EXPECT_GT(cloud / (64 * 36), 0.05) << "the view shows a cloud";
    EXPECT_LT(diff / (64 * 36), 0.03);
    EXPECT_FALSE(full.image == coarse.image);
    EXPECT_THROW(preview::set_preview_options(po, {{"pixel_size", "9"}}), Error);
}

// Issue 41: the preview's sky_occlusion (default 0.1) only dims the ambient under cloud:
// the same transmittance, and no pixel brighter with more occlusion (1 = Beer straight up).
TEST(GraphPreview, SkyOcclusionDimsTheAmbientUnderCloudOnly) {
    preview::GraphPreviewOptions how;
    render::PreviewOptions po = orbit_picture(how);
    Session s = cloud_session();
    EXPECT_EQ(po.sky_occlusion, render::kPreviewSkyOcclusion);
    const render::PreviewFrame relaxed = preview::preview_session(s, po, how);
    preview::set_preview_options(po, {{"sky_occlusion", "1"}});
    const render::PreviewFrame beer = preview::preview_session(s, po, how);
    double darker = 0;
    for (int y = 0; y < 36; ++y)
        for (int x = 0; x < 64; ++x) {
            ASSERT_EQ(relaxed.image.at(3, x, y), beer.image.at(3, x, y)) << x << "," << y;
            for (int c = 0; c < 3; ++c) {
                ASSERT_LE(beer.image.at(c, x, y), relaxed.image.at(c, x, y) + 1e-6f) << x << "," << y;
                darker += relaxed.image.at(c, x, y) - beer.image.at(c, x, y);
            }
        }
    EXPECT_GT(darker, 0.0) << "cloud with cloud above it is dimmer with full occlusion";
    EXPECT_THROW(preview::set_preview_options(po, {{"sky_occlusion", "-1"}}), Error);
}

// Issue 43: a graph's lightning schedule (ndf/lightning's table) is drawn: the window's
// longest strike sequence becomes point lights at its flashes, with their intensities;
// flash_schedule false leaves them out, and a window without flashes adds none.
TEST(GraphPreview, TheLightningScheduleLightsTheStorm) {
    const std::string graph = R"(atlas: 1
nodes:
  set:
    type: ndf/set
    params: {resolution: [32, 32], bounds_max: [20000, 20000], coverage: 0.3, min_height: 1500, max_height: 4000}
  storm:
    type: ndf/superstorm
    inputs: {in: set}
    params: {center: [10000, 10000], radius: 5000, blend: 1, max_height: 12000, min_height: 800}
  lightning:
    type: ndf/lightning
    inputs: {in: storm}
    params: {time: 100, window: 60, rate: 20, intra_flashes: 3, ground_max: 2, intensity: 2e6, seed: 3}
outputs:
  - {node: storm, file: storm.exr}
  - {node: lightning, port: table, file: lightning.json}
)";
    Session s(builtin_nodes());
    s.load_text(graph, "storm.yaml", ".");
    // The table itself, to know what to expect.
    const Field2DPtr table = std::get<Field2DPtr>(s.get("lightning", "table", values(1)));
    const int seq = table->find_channel("sequence"), in = table->find_channel("intensity");
    std::map<double, int> per_sequence;
    for (int i = 0; i < table->width(); ++i)
        if (table->at(in, i, 0) > 0) ++per_sequence[table->at(seq, i, 0)];
    ASSERT_GE(per_sequence.size(), 2u) << "the test wants a window with several sequences";
    int longest = 0;
    for (const auto& [k, n] : per_sequence) longest = std::max(longest, n);

    preview::GraphPreviewOptions how;
    render::PreviewOptions po = small_picture();
    const preview::GraphPreview lit = preview::prepare_graph_preview(s, po, how, "storm.yaml");
    ASSERT_TRUE(lit.layer);
    ASSERT_EQ(int(lit.job.settings.lights.size()), longest);
    for (const auto& l : lit.job.settings.lights) {
        EXPECT_GT(l.intensity, 0.0);
        EXPECT_LE(l.intensity, 2e6);
        EXPECT_GE(l.position[2], 800.0 - 1e-6);
        EXPECT_LE(l.position[2], 12000.0 + 1e-6);
    }
    const render::PreviewFrame with = render::render_preview(lit.job);

    preview::set_preview_options(po, {{"flash_schedule", "false"}});
    const preview::GraphPreview dark = preview::prepare_graph_preview(s, po, how, "storm.yaml");
    EXPECT_TRUE(dark.job.settings.lights.empty());
    EXPECT_FALSE(render::render_preview(dark.job).image == with.image) << "the flashes changed nothing on screen";

    s.set_text("lightning", "rate", "0");
    const preview::GraphPreview none = preview::prepare_graph_preview(s, small_picture(), how, "storm.yaml");
    EXPECT_TRUE(none.job.settings.lights.empty());
}

// `atlas preview` picking its mode from what a graph writes: an NDF set ->
// 2.5D, an NVDF set -> voxel, both -> one composited picture; --mode
// overrides; a graph that writes neither, a camera under the ground and
// --set reach the user as clear messages; --jobs never changes the bytes.
#include "atlas/core/files.h"
#include "atlas/io/exr.h"
#include "atlas/io/readers.h"

#include "../support/cli_run.h"

#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <sys/wait.h>
#include <unistd.h>

namespace fs = std::filesystem;

namespace {

using atlas::test::CliRun;

fs::path work_dir() { return atlas::test::process_dir("atlas_layer_cli"); }

// Runs atlas with a cache shared by the tests of this file (the HZD noise
// cooks once).
CliRun run_atlas(const std::string& args) {
    const fs::path dir = work_dir();
    return atlas::test::run_shell("cd " + dir.string() + " && ATLAS_CACHE_DIR= " + atlas::test::atlas_program() + " " + args + " --cache " +
                                      (dir / "cache").string() + " 2>err.txt",
                                  dir / "err.txt");
}

const char* kLayerGraph = R"(atlas: 1
nodes:
  coverage_noise:
    type: ndf/noise
    params: {resolution: [32, 32], bounds_max: [20000, 20000], period: [3, 3], octaves: 3, seed: 5}
  set:
    type: ndf/set
    inputs: {coverage: coverage_noise}
    params: {type: 0.6, min_height: 1500, max_height: 3500}
outputs:
  - {node: set, file: set.exr}
)";

const char* kVoxelNodes = R"(
  base:
    type: noise/value
    params: {resolution: [16, 16, 8], bounds_min: [9000, 4000, 1600], bounds_max: [10600, 5600, 2400], period: [2, 2, 1], octaves: 2, seed: 3}
  coverage:
    type: math/remap
    inputs: {in: base}
    params: {in_min: 0.4, in_max: 0.56, out_min: 0, out_max: 1, clamp: true}
  distance:
    type: volume/sdf
    inputs: {in: coverage}
    params: {iso: 0.5}
  nvdf:
    type: volume/nvdf
    inputs: {sdf: distance}
    params: {depth: 32}
)";

void write(const std::string& name, const std::string& text) { std::ofstream(work_dir() / name) << text; }

// The work directory holds a cache with the HZD and Nubis noise (~100 MB): it lives in
// the process's private TMPDIR, which the suites' main() removes at exit
// (tests/support/gtest_main.cpp).
} // namespace

TEST(LayerCli, NdfSetGraphRendersInLayerModeSameBytesForAnyJobs) {
    write("layer.yaml", kLayerGraph);
    const CliRun a = run_atlas("preview layer.yaml --size 48x27 --jobs 1 -o a.png");
    ASSERT_EQ(a.status, 0) << a.err;
    EXPECT_NE(a.err.find("(2.5D)"), std::string::npos) << a.err;
    EXPECT_NE(a.err.find("curved_earth"), std::string::npos) << a.err;
    const CliRun b = run_atlas("preview layer.yaml --size 48x27 --jobs 2 -o b.png");
    ASSERT_EQ(b.status, 0) << b.err;
    EXPECT_EQ(atlas::read_file_bytes(work_dir() / "a.png"), atlas::read_file_bytes(work_dir() / "b.png"));
    // The graph's own outputs are not written.
    EXPECT_FALSE(fs::exists(work_dir() / "set.exr"));
    // --set reaches the graph: a different seed, a different picture.
    const CliRun c = run_atlas("preview layer.yaml --size 48x27 --set coverage_noise.seed=9 -o c.png");
    ASSERT_EQ(c.status, 0) << c.err;
    EXPECT_NE(atlas::read_file_bytes(work_dir() / "a.png"), atlas::read_file_bytes(work_dir() / "c.png"));
    for (const char* v : {"orbit:120,30"}) {
        const CliRun d = run_atlas(std::string("preview layer.yaml --size 32x18 --view ") + v + " -o d.png");
        EXPECT_EQ(d.status, 0) << v << ": " << d.err;
    }
}

TEST(LayerCli, BothSetsComposeOneImageAndModeOverrides) {
    std::string g = kLayerGraph;
    g.insert(g.find("outputs:"), std::string(kVoxelNodes).substr(1));
    g += "  - {node: nvdf, port: vdb_set, file: nvdf.vdb}\n";
    write("both.yaml", g);
    const CliRun both = run_atlas("preview both.yaml --noise none --size 48x27 -o both.png");
    ASSERT_EQ(both.status, 0) << both.err;
    EXPECT_NE(both.err.find("2.5D + voxel composited"), std::string::npos) << both.err;
    const CliRun layer = run_atlas("preview both.yaml --noise none --size 48x27 --mode layer -o layer.png");
    ASSERT_EQ(layer.status, 0) << layer.err;
    EXPECT_NE(layer.err.find("(2.5D)"), std::string::npos) << layer.err;
    const CliRun voxel = run_atlas("preview both.yaml --noise none --size 48x27 --mode voxel -o voxel.png");
    ASSERT_EQ(voxel.status, 0) << voxel.err;
    EXPECT_NE(voxel.err.find("(voxel)"), std::string::npos) << voxel.err;
    write("layer.yaml", kLayerGraph); // ctest runs each test in its own process and directory
    const CliRun bad = run_atlas("preview layer.yaml --size 48x27 --mode voxel -o x.png");
    EXPECT_NE(bad.status, 0);
    EXPECT_NE(bad.err.find("no volume/nvdf"), std::string::npos) << bad.err;
}

TEST(LayerCli, GraphWithNothingToPreviewListsWhatItWrites) {
    write("mesh_only.yaml", R"(atlas: 1
nodes:
  lut:
    type: ndf/profile_lut
    params: {resolution: [8, 8]}
outputs:
  - {node: lut, file: lut.exr}
)");
    const CliRun r = run_atlas("preview mesh_only.yaml -o x.png");
    EXPECT_NE(r.status, 0);
    EXPECT_NE(r.err.find("writes nothing to preview"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("node 'lut' (ndf/profile_lut) port 'out' -> lut.exr"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(work_dir() / "x.png"));
}

TEST(LayerCli, CameraUnderTheGroundIsAClearMessage) {
    write("layer.yaml", kLayerGraph);
    const CliRun r = run_atlas("preview layer.yaml --size 32x18 --camera 10000,10000,-50,10000,20000,0 -o x.png");
    EXPECT_NE(r.status, 0);
    EXPECT_NE(r.err.find("under the ground"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(work_dir() / "x.png"));
}

TEST(LayerCli, TimeSequenceWritesNumberedFramesThatMove) {
    write("layer.yaml", kLayerGraph);
    const CliRun r = run_atlas("preview layer.yaml --size 32x18 --frames 3 --time-step 900 --lightning 2 -o seq.png");
    ASSERT_EQ(r.status, 0) << r.err;
    for (const char* f : {"seq_000.png", "seq_001.png", "seq_002.png"}) EXPECT_TRUE(fs::exists(work_dir() / f)) << f;
    EXPECT_NE(atlas::read_file_bytes(work_dir() / "seq_000.png"), atlas::read_file_bytes(work_dir() / "seq_001.png"));
    const CliRun bad = run_atlas("preview layer.yaml --size 32x18 --frames 2 --turntable 2 -o x.png");
    EXPECT_NE(bad.status, 0);
}

TEST(LayerCli, NonFiniteChannelNamesNodeAndChannel) {
    atlas::Field2D f({{4, 4}}, 3, atlas::Box2d{{{0, 0}}, {{4000, 4000}}}, {"coverage", "min_height", "max_height"});
    for (int y = 0; y < 4; ++y)
        for (int x = 0; x < 4; ++x) f.at(0, x, y) = 0.5f, f.at(1, x, y) = 1500, f.at(2, x, y) = 3000;
    f.at(0, 2, 3) = std::numeric_limits<float>::infinity();
    atlas::io::write_exr(f, work_dir() / "inf_set.exr");
    write("inf.yaml", "atlas: 1\nnodes:\n  weather: {type: import/exr, params: {file: inf_set.exr}}\noutputs:\n  - {node: weather, file: w.exr}\n");
    const CliRun r = run_atlas("preview inf.yaml --size 16x9 -o x.png");
    EXPECT_NE(r.status, 0);
    EXPECT_NE(r.err.find("node 'weather' output 'out': channel 'coverage' holds Inf at texel (2, 3)"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(work_dir() / "x.png"));
}

TEST(LayerCli, WatchReRendersWhenTheGraphChangesAndKeepsWhatItCooked) {
    const fs::path dir = work_dir();
    write("watch.yaml", kLayerGraph);
    fs::remove(dir / "w.png");
    // In the background (timeout: never outlives the test): one preview, then one re-render.
    // No disk cache: what the second round does not cook comes from the watch's memory.
    const std::string cmd = "cd " + dir.string() + " && ATLAS_CACHE_DIR= timeout 120 " + std::string(ATLAS_BINARY_DIR) +
                            "/bin/atlas preview watch.yaml --size 24x14 --watch --watch-max 1 --no-cache -o w.png 2>watch_err.txt &";
    ASSERT_EQ(std::system(cmd.c_str()), 0);
    auto log_text = [&] {
        std::ifstream in(dir / "watch_err.txt");
        return std::string(std::istreambuf_iterator<char>(in), {});
    };
    auto wait_for = [&](auto&& ok) {
        for (int i = 0; i < 1200 && !ok(); ++i) ::usleep(50000);
        return ok();
    };
    ASSERT_TRUE(wait_for([&] { return log_text().find("watch: waiting") != std::string::npos; }))
        << log_text();
    const std::string first = atlas::read_file_bytes(dir / "w.png");
    std::string g = kLayerGraph;
    g.replace(g.find("type: 0.6"), 9, "type: 0.9");
    write("watch.yaml", g);
    ASSERT_TRUE(wait_for([&] { return log_text().find("re-cooked and re-rendered") != std::string::npos; }))
        << log_text();
    const std::string log = log_text();
    const size_t changed = log.find("watch.yaml changed");
    ASSERT_NE(changed, std::string::npos) << log;
    // Only the edited node cooks; the noise it reads and the preview's built-in noise sets are kept.
    const std::string second = log.substr(changed);
    EXPECT_NE(second.find("graph: cooked 1, cached 1 nodes"), std::string::npos) << log;
    EXPECT_EQ(second.find("noise/hzd_set"), std::string::npos) << log;
    EXPECT_NE(atlas::read_file_bytes(dir / "w.png"), first);
}

TEST(LayerCli, ForecastSequenceStepsTheSlices) {
    // ndf/forecast writes a stack of weather maps; --frames draws one slice per frame.
    const std::string fc = std::string(ATLAS_SOURCE_DIR) + "/graphs/fc6/forecast.yaml";
    write("forecast.yaml", "atlas: 1\nnodes:\n  f: {type: ndf/forecast, params: {forecast: '" + fc +
                               "', resolution: [24, 24], bounds_max: [30000, 30000], start_hour: 60, step_hours: 6, slices: 3, octaves: 2}}\n"
                               "outputs:\n  - {node: f, port: maps, file: maps.exr}\n");
    const CliRun r = run_atlas("preview forecast.yaml --size 24x14 --view aerial --frames 2 --time-step 0 -o fc.png");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.err.find("(2.5D)"), std::string::npos) << r.err;
    // Same time, different slices: different pictures.
    EXPECT_NE(atlas::read_file_bytes(work_dir() / "fc_000.png"), atlas::read_file_bytes(work_dir() / "fc_001.png"));
    const CliRun bad = run_atlas("preview forecast.yaml --size 24x14 --slice 3 -o x.png");
    EXPECT_NE(bad.status, 0);
    EXPECT_NE(bad.err.find("time slices (0..2)"), std::string::npos) << bad.err;
}

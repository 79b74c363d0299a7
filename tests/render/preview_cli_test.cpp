// `atlas preview` as a user runs it: a graph preview goes through the disk
// cache (the second run cooks nothing), pictures are written atomically (a
// failed render or write leaves no file and keeps an existing one), and the
// light and sky options reach the renderer.
#include "atlas/core/files.h"
#include "atlas/io/readers.h"

#include "../support/cli_run.h"

#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sys/wait.h>
#include <unistd.h>

namespace fs = std::filesystem;

namespace {

using atlas::test::CliRun;

fs::path work_dir() { return atlas::test::process_dir("atlas_preview_cli"); }

CliRun run_atlas(const std::string& args) {
    const fs::path dir = work_dir();
    return atlas::test::run_shell("cd " + dir.string() + " && ATLAS_CACHE_DIR= " + atlas::test::atlas_program() + " " + args + " 2>err.txt",
                                  dir / "err.txt");
}

// A tiny graph: noise -> remap -> sdf -> nvdf, writing the NVDF set.
void write_graph() {
    std::ofstream(work_dir() / "tiny.yaml") << R"(atlas: 1
nodes:
  base:
    type: noise/value
    params: {resolution: [24, 24, 8], bounds_min: [0, 0, 0], bounds_max: [960, 960, 320], period: [2, 2, 1], octaves: 2, seed: 3}
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
    params: {depth: 64}
outputs:
  - node: nvdf
    port: vdb_set
    file: nvdf.vdb
)";
}

std::vector<std::string> leftovers(const fs::path& dir) {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
    return names;
}

} // namespace

TEST(PreviewCli, SecondPreviewOfAGraphComesFromTheDiskCache) {
    write_graph();
    fs::remove_all(work_dir() / "cache");
    CliRun first = run_atlas("preview tiny.yaml --noise none --size 32x18 --cache cache -o first.png");
    ASSERT_EQ(first.status, 0) << first.err;
    EXPECT_NE(first.err.find("graph: cooked 4, cached 0"), std::string::npos) << first.err;
    EXPECT_FALSE(fs::is_empty(work_dir() / "cache"));
    // A new process: only the disk cache can save the cook.
    CliRun second = run_atlas("preview tiny.yaml --noise none --size 32x18 --cache cache -o second.png");
    ASSERT_EQ(second.status, 0) << second.err;
    EXPECT_NE(second.err.find("graph: cooked 0, cached 1"), std::string::npos) << second.err;
    EXPECT_EQ(atlas::read_file_bytes(work_dir() / "first.png"), atlas::read_file_bytes(work_dir() / "second.png"));
    EXPECT_FALSE(fs::exists(work_dir() / "nvdf.vdb")) << "a preview must not write the graph's outputs";
    CliRun nocache = run_atlas("preview tiny.yaml --noise none --size 32x18 --no-cache -o third.png");
    ASSERT_EQ(nocache.status, 0) << nocache.err;
    EXPECT_NE(nocache.err.find("graph: cooked 4, cached 0"), std::string::npos) << nocache.err;
    EXPECT_EQ(run_atlas("preview tiny.yaml --noise none --cache c --no-cache -o x.png").status, 2);
    // A graph with another positional argument is a usage error that says so (it was read as a
    // file list: "unknown file type '.yaml'").
    CliRun two = run_atlas("preview tiny.yaml stray -o y.png");
    EXPECT_EQ(two.status, 2) << two.err;
    EXPECT_NE(two.err.find("a graph is previewed alone: 'tiny.yaml' was given with 1 more file(s)"), std::string::npos) << two.err;
    EXPECT_FALSE(fs::exists(work_dir() / "y.png"));
}

TEST(PreviewCli, FailedRenderOrWriteLeavesNoPartialFile) {
    write_graph();
    const fs::path dir = work_dir() / "atomic";
    fs::remove_all(dir);
    fs::create_directories(dir);
    std::ofstream(dir / "keep.png") << "the previous picture";
    // The render fails (a negative light intensity): the old file is untouched.
    CliRun bad_light = run_atlas("preview tiny.yaml --noise none --size 16x9 --light 1,2,3,1,1,1,-5 -o atomic/keep.png");
    EXPECT_EQ(bad_light.status, 1) << bad_light.err;
    EXPECT_NE(bad_light.err.find("intensity"), std::string::npos) << bad_light.err;
    EXPECT_EQ(atlas::read_file_bytes(dir / "keep.png"), "the previous picture");
    // The write fails (no writer for the extension): nothing is left behind.
    CliRun bad_ext = run_atlas("preview tiny.yaml --noise none --size 16x9 -o atomic/out.unknownext");
    EXPECT_EQ(bad_ext.status, 1) << bad_ext.err;
    EXPECT_EQ(leftovers(dir), std::vector<std::string>{"keep.png"});
    CliRun bad_turntable = run_atlas("preview tiny.yaml --noise none --size 16x9 --turntable 2 -o atomic/spin.unknownext");
    EXPECT_EQ(bad_turntable.status, 1);
    EXPECT_EQ(leftovers(dir), std::vector<std::string>{"keep.png"});
    CliRun ok = run_atlas("preview tiny.yaml --noise none --size 16x9 --turntable 2 -o atomic/spin.png");
    ASSERT_EQ(ok.status, 0) << ok.err;
    EXPECT_TRUE(fs::exists(dir / "spin_000.png") && fs::exists(dir / "spin_001.png"));
}

TEST(PreviewCli, LightAndSkyOptions) {
    write_graph();
    CliRun r = run_atlas("preview tiny.yaml --noise none --size 24x14 --sky 0.1,0.3,0.9,0.9,0.8,0.6 --light 480,480,160,1,0.3,0.1,1e5 "
                  "--light 100,100,100,0,0,1,1e4,200 -o lit.exr");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.err.find("point_lights"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("sky_gradient"), std::string::npos) << r.err;
    CliRun plain = run_atlas("preview tiny.yaml --noise none --size 24x14 -o plain.exr");
    ASSERT_EQ(plain.status, 0) << plain.err;
    EXPECT_EQ(plain.err.find("point_lights"), std::string::npos) << plain.err;
    // The graph has clouds in view, and the lights brighten them (the same
    // transmittance, more radiance where a cloud is seen against the sky).
    auto lit = std::get<atlas::Field2DPtr>(atlas::io::read_field_file(work_dir() / "lit.exr"));
    auto flat = std::get<atlas::Field2DPtr>(atlas::io::read_field_file(work_dir() / "plain.exr"));
    ASSERT_EQ(lit->channels(), 4);
    float min_t = 1;
    for (float t : flat->channel(3)) min_t = std::min(min_t, t);
    EXPECT_LT(min_t, 0.5f) << "the test graph should show clouds";
    for (size_t i = 0; i < flat->channel(3).size(); ++i) ASSERT_EQ(lit->channel(3)[i], flat->channel(3)[i]);
    for (const char* bad : {"--light 1,2,3", "--light 1,2,3,4,5,6,7,8,9", "--light a,2,3,4,5,6,7", "--sky 1,2,3"}) {
        CliRun e = run_atlas(std::string("preview tiny.yaml --noise none --size 8x8 ") + bad + " -o e.png");
        EXPECT_EQ(e.status, 2) << bad << ": " << e.err;
        EXPECT_NE(e.err.find(std::string(bad).substr(0, 5)), std::string::npos) << e.err;
    }
}

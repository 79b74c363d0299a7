// Issue 41's bad input: shapes that leave the grid, a condensation height above
// the cloud, and the graph's own clouds fitting their grid: clear messages that
// name the node and the parameter.
#include "atlas/core/files.h"

#include "../support/cli_run.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <unistd.h>

namespace fs = std::filesystem;
using atlas::test::CliRun;

namespace {
fs::path dir() { return atlas::test::process_dir("atlas_authoring_input"); }
CliRun run(const std::string& args) {
    return atlas::test::run_shell("cd " + dir().string() + " && " + atlas::test::atlas_program() + " " + args + " 2>err.txt", dir() / "err.txt");
}
const std::string kBalls = "atlas: 1\nnodes:\n  m:\n    type: volume/metaballs\n    params: {resolution: [16, 16, 8], bounds_max: [160, 160, 80], spheres: '";
} // namespace

TEST(AuthoringInput, SpheresOutsideTheGridAreNamed) {
    std::ofstream(dir() / "out.yaml") << kBalls << "500 500 500 10'}\noutputs:\n  - {node: m, file: m.exr}\n";
    CliRun r = run("cook out.yaml --out o --no-cache --quiet");
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.err.find("node 'm' (volume/metaballs): every sphere lies outside the grid"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("'bounds_max'"), std::string::npos) << r.err;
    // Some outside, some cut: the cook goes on and warns (also under --quiet).
    std::ofstream(dir() / "some.yaml") << kBalls << "80 80 40 20; 500 500 500 10; 150 80 40 30'}\noutputs:\n  - {node: m, file: m.exr}\n";
    r = run("cook some.yaml --out o --no-cache --quiet");
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.err.find("1 of 3 spheres lie outside"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("1 spheres cross the faces"), std::string::npos) << r.err;
}

TEST(AuthoringInput, ACondensationHeightAboveTheCloudIsRefused) {
    std::ofstream(dir() / "base.yaml") << kBalls
                                       << "80 80 40 20'}\n  s:\n    type: volume/sdf\n    inputs: {in: m}\n    params: {iso: 0.5}\n"
                                          "  p:\n    type: volume/cumulus_paint\n    inputs: {sdf: s}\n    params: {base_height: 300}\n"
                                          "outputs:\n  - {node: p, port: detail_type, file: t.exr}\n";
    CliRun r = run("cook base.yaml --out o --no-cache --quiet");
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.err.find("node 'p' (volume/cumulus_paint): 'base_height' 300"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("above the cloud's top"), std::string::npos) << r.err;
}

// The shipped cumulus graphs fit their grids: no sphere cut or lost.
TEST(AuthoringInput, TheShippedCumulusFitsItsGrid) {
    CliRun r = run("cook " + std::string(ATLAS_SOURCE_DIR) + "/graphs/towering_cumulus.yaml --out tc --no-cache --output towering_cumulus.vdb");
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(r.err.find("warning"), std::string::npos) << r.err;
}

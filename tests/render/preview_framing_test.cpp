// Issue 41: the default cameras frame the clouds (a third to two thirds of the
// frame height), plain density grids are drawn as they are (no foam) and their
// units are read, and a picture that would be empty says why.
#include "atlas/core/field.h"
#include "atlas/io/readers.h"

#include "../support/cli_run.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

namespace fs = std::filesystem;
using atlas::test::CliRun;

namespace {
fs::path dir() { return atlas::test::process_dir("atlas_preview_framing"); }

CliRun atlas_run(const std::string& args) {
    return atlas::test::run_shell("cd " + dir().string() + " && ATLAS_CACHE_DIR= " + atlas::test::atlas_program() + " " + args + " 2>err.txt",
                                  dir() / "err.txt");
}

// One cumulus-sized blob (metaballs, 300 m) in a 4 km x 4 km x 1 km box,
// written as a plain density grid (weight scales its values).
void write_blob(const std::string& name, double weight) {
    std::ofstream(dir() / "blob.yaml") << "atlas: 1\nnodes:\n  m:\n    type: volume/metaballs\n    params: {resolution: [96, 96, 24], "
                                          "bounds_max: [4096, 4096, 1024], spheres: '1200 2600 400 160; 1350 2650 450 120', weight: "
                                       << weight << "}\noutputs:\n  - {node: m, file: " << name << "}\n";
    ASSERT_EQ(atlas_run("cook blob.yaml --out . --no-cache --quiet").status, 0);
}

// Fraction of the frame's rows holding cloud (view transmittance under 0.98).
double rows_filled(const fs::path& exr) {
    const atlas::Field3DPtr f = atlas::io::as_field3d(atlas::io::read_field_file(exr));
    const int t = f->find_channel("transmittance");
    EXPECT_GE(t, 0);
    int lo = f->ny(), hi = -1;
    for (int y = 0; y < f->ny(); ++y)
        for (int x = 0; x < f->nx(); ++x)
            if (f->at(t, x, y, 0) < 0.98f) lo = std::min(lo, y), hi = std::max(hi, y);
    return hi < lo ? 0.0 : double(hi - lo + 1) / f->ny();
}
} // namespace

TEST(PreviewFraming, DefaultViewsFillAThirdToTwoThirdsOfTheFrame) {
    write_blob("blob.vdb", 2);
    for (const std::string view : {"", "--view orbit", "--view ground", "--view aerial"}) {
        CliRun r = atlas_run("preview blob.vdb -o f.exr --size 160x90 --quiet --noise none " + view);
        ASSERT_EQ(r.status, 0) << view << ": " << r.err;
        const double fill = rows_filled(dir() / "f.exr");
        EXPECT_GE(fill, 1.0 / 3) << "'" << view << "'";
        EXPECT_LE(fill, 2.0 / 3 + 0.05) << "'" << view << "'";
    }
}

TEST(PreviewFraming, TheGroundViewStandsClearOfCloudsWhoseBasesFloatHigh) {
    // Bases at 1.2 km over a ground at 0: the camera stands below them, where the clouds' angular
    // height first grows with the distance; the search for the distance that frames them stood
    // the camera right under a cloud (a dark underside filled the frame: the tutorial's field).
    std::ofstream(dir() / "high.yaml") << "atlas: 1\nnodes:\n  m:\n    type: volume/metaballs\n    params: {resolution: [96, 96, 48], "
                                          "bounds_max: [4096, 4096, 2048], kernel: sphere, spheres: '1200 2600 1500 300; 1500 2700 1600 250; "
                                          "2800 1400 1450 220'}\noutputs:\n  - {node: m, file: high.vdb}\n";
    ASSERT_EQ(atlas_run("cook high.yaml --out . --no-cache --quiet").status, 0);
    CliRun r = atlas_run("preview high.vdb -o h.exr --size 160x90 --quiet --noise none --view ground");
    ASSERT_EQ(r.status, 0) << r.err;
    const double fill = rows_filled(dir() / "h.exr");
    EXPECT_GE(fill, 1.0 / 3);
    EXPECT_LE(fill, 2.0 / 3 + 0.05);
}

TEST(PreviewFraming, ADensityGridIsDrawnAsItIsAndItsUnitsAreRead) {
    // Cloud water as a solver writes it: mixing ratios around 0.003 kg/kg.
    write_blob("qc.vdb", 0.003);
    CliRun r = atlas_run("preview qc.vdb -o q.exr --size 160x90");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.err.find("noise: none for a plain density grid"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("density units: kg/kg"), std::string::npos) << r.err;
    EXPECT_GT(rows_filled(dir() / "q.exr"), 0.2); // visible
    // Read as density, the same values are almost nothing: the preview says so.
    r = atlas_run("preview qc.vdb -o d.exr --size 160x90 --density-units density");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.err.find("nearly empty"), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find("density units: kg/kg"), std::string::npos) << r.err;
}

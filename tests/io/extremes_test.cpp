// Degenerate sizes, extreme coordinates, determinism and memory limits.
#include "atlas/io/exr.h"
#include "atlas/io/image.h"
#include "atlas/io/tga_slices.h"
#include "atlas/io/vdb.h"
#include "atlas/io/writers.h"

#include "io_test_util.h"

using namespace atlas;
using namespace atlas::io;
using namespace atlas::io::test;

TEST(Extremes, SingleVoxelFieldsRoundTripInEveryFormat) {
    TempDir dir;
    const Box3d b{{{5, 6, 7}}, {{5.5, 6.25, 7.125}}};
    Field3D f({{1, 1, 1}}, 1, b, {"d"});
    f.at(0, 0, 0, 0) = 0.75f;
    write_exr(f, dir / "one.exr");
    EXPECT_EQ(*std::get<Field3DPtr>(read_exr(dir / "one.exr")), f);
    write_vdb(f, dir / "one.vdb");
    EXPECT_EQ(read_vdb(dir / "one.vdb"), f);
    auto files = write_tga_slices(f, dir.path(), "one");
    Field3D t = read_tga_slices(files[0], b, 1);
    EXPECT_NEAR(t.at(0, 0, 0, 0), 0.75f, 0.5f / 255.0f);
    Field2D g({{1, 1}}, 1, Box2d{{{0, 0}}, {{1, 1}}});
    g.at(0, 0, 0) = 1.0f;
    write_image(g, dir / "one.png");
    EXPECT_EQ(read_image(dir / "one.png").at(0, 0, 0), 1.0f);
}

// Bounds far from the origin and tiny or huge voxels survive exactly.
TEST(Extremes, ExtremeBoundsRoundTripExactly) {
    TempDir dir;
    const std::vector<Box3d> boxes = {
        {{{1e12, -1e12, 3e11}}, {{1e12 + 4096, -1e12 + 4096, 3e11 + 512}}},
        {{{-1e-6, 0.0, 1e-9}}, {{1e-6, 3e-9, 2e-9}}},
        {{{-1e15, -1e15, -1e15}}, {{1e15, 1e15, 1e15}}},
    };
    int n = 0;
    for (const Box3d& b : boxes) {
        SCOPED_TRACE(n);
        Field3D f = make_field3d({{4, 3, 2}}, b, {"d"}, [](int x, int y, int z, int c) { return 1.0f + float(x + y + z + c); });
        const fs::path e = dir / ("b" + std::to_string(n) + ".exr"), v = dir / ("b" + std::to_string(n) + ".vdb");
        ++n;
        write_exr(f, e);
        EXPECT_EQ(std::get<Field3DPtr>(read_exr(e))->bounds(), b);
        if (f.voxel_size()[0] * f.voxel_size()[1] * f.voxel_size()[2] < 3e-15) {
            // OpenVDB's transform refuses scales with determinant < 3e-15: a clear error, not a crash.
            expect_error_containing([&] { write_vdb(f, v); }, {v.filename().string(), "voxel size"});
            continue;
        }
        write_vdb(f, v);
        Field3D r = read_vdb(v);
        EXPECT_EQ(r.bounds(), b);
        EXPECT_EQ(r, f);
    }
}

TEST(Extremes, SameFieldSameBytesInEveryFormat) {
    TempDir a, b;
    auto f = std::make_shared<Field3D>(make_field3d({{8, 6, 4}}, Box3d{{{0, 0, 0}}, {{8, 6, 4}}}, {"r", "g", "b", "a"},
                                                    [](int x, int y, int z, int c) { return unit_float(51, x, y, z, c); }));
    for (TempDir* d : {&a, &b}) {
        write_value(f, *d / "x.exr", "exr", {});
        write_value(f, *d / "h.exr", "exr", {{"half", "1"}});
        write_value(f, *d / "x.png", "png", {{"bits", "16"}});
        write_value(f, *d / "x.tga", "tga", {{"montage", "1"}});
        write_value(f, *d / "x.vdb", "vdb", {{"tolerance", "0.1"}});
        write_value(f, *d / "s", "tga-slices", {});
    }
    int files = 0;
    for (const auto& e : fs::directory_iterator(a.path())) {
        ++files;
        EXPECT_EQ(read_bytes(e.path()), read_bytes(b.path() / e.path().filename())) << e.path().filename();
    }
    EXPECT_EQ(files, 5 + 4);
}

TEST(Extremes, MemoryBudgetIsCheckedBeforeReading) {
    TempDir dir;
    Field3D f({{64, 64, 8}}, 2, Box3d{{{0, 0, 0}}, {{1, 1, 1}}});
    f.at(0, 1, 2, 3) = 1.0f;
    write_exr(f, dir / "f.exr");
    write_vdb(f, dir / "f.vdb");
    Field2D g({{64, 64}}, 4, Box2d{{{0, 0}}, {{1, 1}}});
    write_image(g, dir / "f.png");
    auto slices = write_tga_slices(f, dir.path(), "s");
    const MemoryBudget tiny(1000);
    auto expect_budget_error = [](auto&& fn, const std::string& file) {
        try {
            fn();
            ADD_FAILURE() << "expected a MemoryBudgetError for " << file;
        } catch (const MemoryBudgetError& e) {
            EXPECT_NE(std::string(e.what()).find(file), std::string::npos) << e.what();
        }
    };
    expect_budget_error([&] { read_exr(dir / "f.exr", &tiny); }, "f.exr");
    expect_budget_error([&] { read_vdb(dir / "f.vdb", {}, &tiny); }, "f.vdb");
    expect_budget_error([&] { read_image(dir / "f.png", std::nullopt, &tiny); }, "f.png");
    expect_budget_error([&] { read_tga_slices(slices[0], f.bounds(), 4, &tiny); }, "s.001.tga");
}

// An EXR header whose data window claims a 100000 x 100000 image must be
// refused (budget or format error), not allocated.
TEST(Extremes, CorruptExrHeaderClaimingAHugeImageIsRefused) {
    TempDir dir;
    Field2D f({{4, 4}}, 1, Box2d{{{0, 0}}, {{1, 1}}});
    write_exr(f, dir / "f.exr");
    std::string bytes = read_bytes(dir / "f.exr");
    const std::string key = std::string("dataWindow") + '\0' + "box2i" + '\0';
    const size_t at = bytes.find(key);
    ASSERT_NE(at, std::string::npos);
    const size_t box = at + key.size() + 4; // after the attribute size
    const int32_t big = 99999;
    std::memcpy(&bytes[box + 8], &big, 4);
    std::memcpy(&bytes[box + 12], &big, 4);
    write_bytes(dir / "huge.exr", bytes);
    expect_error_containing([&] { read_exr(dir / "huge.exr"); }, {"huge.exr"});
}

#include "atlas/io/tga_slices.h"

#include "io_test_util.h"

#include <algorithm>

using namespace atlas;
using namespace atlas::io;
using namespace atlas::io::test;

namespace {
std::vector<std::string> names_in(const fs::path& dir) {
    std::vector<std::string> v;
    for (const auto& e : fs::directory_iterator(dir)) v.push_back(e.path().filename().string());
    std::sort(v.begin(), v.end());
    return v;
}
} // namespace

TEST(TgaSlices, FileNamesAreExactlyAsSpecified) {
    TempDir dir;
    Field3D f({{2, 2, 12}}, 1, Box3d{{{0, 0, 0}}, {{1, 1, 1}}});
    auto written = write_tga_slices(f, dir.path(), "cloud");
    ASSERT_EQ(written.size(), 12u);
    std::vector<std::string> expect;
    for (int i = 1; i <= 12; ++i) {
        char buf[32];
        std::snprintf(buf, sizeof buf, "cloud.%03d.tga", i);
        expect.push_back(buf);
        EXPECT_EQ(written[size_t(i - 1)], dir.path() / buf);
    }
    EXPECT_EQ(names_in(dir.path()), expect);
}

TEST(TgaSlices, MoreThan999SlicesUseMoreDigits) {
    TempDir dir;
    Field3D f({{1, 1, 1000}}, 1, Box3d{{{0, 0, 0}}, {{1, 1, 1}}});
    auto written = write_tga_slices(f, dir.path(), "tall");
    ASSERT_EQ(written.size(), 1000u);
    EXPECT_EQ(written.front().filename(), "tall.0001.tga");
    EXPECT_EQ(written.back().filename(), "tall.1000.tga");
    Field3D g = read_tga_slices(written.front(), f.bounds(), 1);
    EXPECT_EQ(g.nz(), 1000);
}

// Checked on the raw bytes (not through OpenImageIO): an uncompressed
// true-colour TGA, 32 bits per pixel with 8 alpha bits, pixels stored BGRA,
// rows bottom-up unless the descriptor's top-left bit says otherwise.
TEST(TgaSlices, EachSliceIs32BitRgbaWithBottomUpRows) {
    TempDir dir;
    const int nx = 3, ny = 2, nz = 2;
    Field3D f({{nx, ny, nz}}, 2, Box3d{{{0, 0, 0}}, {{3, 2, 2}}});
    f.at(0, 2, 0, 1) = 1.0f; // x=2, y=0 (bottom row), z=1 (second slice)
    f.at(1, 0, 1, 0) = 1.0f; // x=0, y=1 (top row), z=0
    SliceOptions o;
    o.default_alpha = 77;
    write_tga_slices(f, dir.path(), "s", o);
    for (int z = 0; z < nz; ++z) {
        char name[16];
        std::snprintf(name, sizeof name, "s.%03d.tga", z + 1);
        const std::string b = read_bytes(dir / name);
        ASSERT_GE(b.size(), size_t(18 + nx * ny * 4)) << name;
        auto u8 = [&](size_t i) { return int(static_cast<unsigned char>(b[i])); };
        EXPECT_EQ(u8(1), 0) << "no colour map";
        EXPECT_EQ(u8(2), 2) << "uncompressed true-colour";
        EXPECT_EQ(u8(12) | (u8(13) << 8), nx);
        EXPECT_EQ(u8(14) | (u8(15) << 8), ny);
        EXPECT_EQ(u8(16), 32) << "bits per pixel";
        EXPECT_EQ(u8(17) & 15, 8) << "alpha bits";
        const bool top_down = (u8(17) & 0x20) != 0;
        const size_t data = 18 + size_t(u8(0));
        for (int row = 0; row < ny; ++row)
            for (int x = 0; x < nx; ++x) {
                const size_t px = data + size_t((row * nx + x) * 4);
                const int y = top_down ? ny - 1 - row : row;
                const int expect_r = f.at(0, x, y, z) > 0 ? 255 : 0, expect_g = f.at(1, x, y, z) > 0 ? 255 : 0;
                EXPECT_EQ(u8(px + 2), expect_r) << name << " x " << x << " y " << y;
                EXPECT_EQ(u8(px + 1), expect_g) << name << " x " << x << " y " << y;
                EXPECT_EQ(u8(px + 0), 0);  // unmapped blue fills with 0
                EXPECT_EQ(u8(px + 3), 77); // unmapped alpha fills with default_alpha
            }
    }
}

TEST(TgaSlices, RoundTripWithinHalfStep) {
    TempDir dir;
    const Box3d b{{{-2048, -2048, 0}}, {{2048, 2048, 512}}};
    Field3D f = make_field3d({{7, 5, 4}}, b, {"r", "g", "b", "a"}, [](int x, int y, int z, int c) { return unit_float(21, x, y, z, c, -2.0f, 6.0f); });
    SliceOptions o;
    o.range_min = -2.0f;
    o.range_max = 6.0f;
    auto files = write_tga_slices(f, dir.path(), "pack", o);
    Field3D g = read_tga_slices(files[0], b, 4);
    EXPECT_EQ(g.resolution(), f.resolution());
    EXPECT_EQ(g.bounds(), b);
    for (int c = 0; c < 4; ++c)
        for (size_t i = 0; i < f.voxel_count(); ++i) {
            const float back = -2.0f + 8.0f * g.channel(c)[i];
            EXPECT_LE(std::fabs(back - f.channel(c)[i]), 8.0f / 255.0f / 2.0f + 1e-5f);
        }
    // Fewer channels keeps the first ones.
    Field3D two = read_tga_slices(files[0], b, 2);
    EXPECT_EQ(two.channels(), 2);
    for (size_t i = 0; i < f.voxel_count(); ++i) EXPECT_EQ(two.channel(1)[i], g.channel(1)[i]);
}

TEST(TgaSlices, ChannelMapPicksAndFills) {
    TempDir dir;
    Field3D f = make_field3d({{2, 2, 2}}, Box3d{{{0, 0, 0}}, {{1, 1, 1}}}, {"d", "t"},
                             [](int x, int y, int z, int c) { return c == 0 ? 0.2f + 0.1f * float(x + y + z) : 0.9f; });
    SliceOptions o;
    o.channel_map = {1, -1, 0, -1};
    o.default_alpha = 0;
    auto files = write_tga_slices(f, dir.path(), "m", o);
    Field3D g = read_tga_slices(files[0], f.bounds(), 4);
    for (int z = 0; z < 2; ++z)
        for (int y = 0; y < 2; ++y)
            for (int x = 0; x < 2; ++x) {
                EXPECT_NEAR(g.at(0, x, y, z), f.at(1, x, y, z), 0.5f / 255.0f + 1e-6f);
                EXPECT_EQ(g.at(1, x, y, z), 0.0f);
                EXPECT_NEAR(g.at(2, x, y, z), f.at(0, x, y, z), 0.5f / 255.0f + 1e-6f);
                EXPECT_EQ(g.at(3, x, y, z), 0.0f);
            }
    o.channel_map = {0, 1, 2};
    expect_error_containing([&] { write_tga_slices(f, dir.path(), "bad", o); }, {"channel map", "4"});
    o.channel_map = {0, 5, -1, -1};
    expect_error_containing([&] { write_tga_slices(f, dir.path(), "bad", o); }, {"5"});
}

TEST(TgaSlices, PatternsFindTheSameStack) {
    TempDir dir;
    Field3D f({{2, 2, 3}}, 1, Box3d{{{0, 0, 0}}, {{1, 1, 1}}});
    f.at(0, 1, 1, 2) = 1.0f;
    write_tga_slices(f, dir.path(), "st");
    for (const char* p : {"st.001.tga", "st.###.tga", "st.%03d.tga", "st.*.tga", "st"}) {
        auto files = find_tga_slices(dir / p);
        ASSERT_EQ(files.size(), 3u) << p;
        EXPECT_EQ(files[2].filename(), "st.003.tga");
        Field3D g = read_tga_slices(dir / p, f.bounds(), 1);
        EXPECT_EQ(g.at(0, 1, 1, 2), 1.0f) << p;
    }
    expect_error_containing([&] { find_tga_slices(dir / "st.002.tga"); }, {"st.002.tga", "001"});
    expect_error_containing([&] { find_tga_slices(dir / "st.tga"); }, {"st.tga", "001"});
    // Stems may contain dots.
    write_tga_slices(f, dir.path(), "cloud.v2");
    EXPECT_EQ(find_tga_slices(dir / "cloud.v2").size(), 3u);
    EXPECT_EQ(find_tga_slices(dir / "cloud.v2.001.tga").size(), 3u);
    expect_error_containing([&] { find_tga_slices(dir / "other.001.tga"); }, {"other.001.tga"});
}

TEST(TgaSlices, GapsAndSizeMismatchesNameTheFile) {
    TempDir dir;
    Field3D f({{2, 2, 6}}, 1, Box3d{{{0, 0, 0}}, {{1, 1, 1}}});
    write_tga_slices(f, dir.path(), "g");
    fs::remove(dir / "g.004.tga");
    fs::remove(dir / "g.005.tga"); // a two-slice gap, then g.006
    expect_error_containing([&] { read_tga_slices(dir / "g.001.tga", f.bounds()); }, {"g.004.tga", "missing"});
    // Size mismatch.
    TempDir dir2;
    write_tga_slices(f, dir2.path(), "h");
    Field3D small({{3, 2, 1}}, 1, Box3d{{{0, 0, 0}}, {{1, 1, 1}}});
    write_tga_slices(small, dir2.path(), "tmp");
    fs::rename(dir2 / "tmp.001.tga", dir2 / "h.003.tga");
    expect_error_containing([&] { read_tga_slices(dir2 / "h.001.tga", f.bounds()); }, {"h.003.tga", "3x2", "2x2"});
    // Garbage in the middle of the stack.
    write_tga_slices(f, dir2.path(), "k");
    write_bytes(dir2 / "k.002.tga", "not a tga at all");
    expect_error_containing([&] { read_tga_slices(dir2 / "k.001.tga", f.bounds()); }, {"k.002.tga"});
}

TEST(TgaSlices, BadArgumentsAreErrors) {
    TempDir dir;
    Field3D f({{2, 2, 2}}, 1, Box3d{{{0, 0, 0}}, {{1, 1, 1}}});
    auto files = write_tga_slices(f, dir.path(), "a");
    expect_error_containing([&] { read_tga_slices(files[0], f.bounds(), 0); }, {"channels", "0"});
    expect_error_containing([&] { read_tga_slices(files[0], f.bounds(), 5); }, {"channels", "5"});
    expect_error_containing([&] { read_tga_slices(files[0], Box3d{{{0, 0, 0}}, {{1, 0, 1}}}); }, {"bounds"});
    expect_error_containing([&] { read_tga_slices(dir / "none.001.tga", f.bounds()); }, {"none.001.tga"});
    expect_error_containing([&] { write_tga_slices(f, dir.path(), ""); }, {"stem"});
    f.at(0, 1, 0, 1) = std::numeric_limits<float>::quiet_NaN();
    expect_error_containing([&] { write_tga_slices(f, dir.path(), "nan"); }, {"NaN", "(1, 0, 1)", "nan.002.tga"});
}

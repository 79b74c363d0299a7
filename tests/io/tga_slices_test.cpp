#include "atlas/io/tga_slices.h"
#include "atlas/io/readers.h"
#include "atlas/io/writers.h"

#include "io_test_util.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cstdio>

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
    o.rle = false;
    write_tga_slices(f, dir.path(), "s", o);
    for (int z = 0; z < nz; ++z) {
        char name[32];
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

// ---------------------------------------------------------------- RLE and the pack's naming

namespace {

// A TGA read by OpenImageIO (the independent reader): 8-bit samples, the
// file's channel count, rows flipped so that row 0 is the BOTTOM (as TgaImage),
// alpha left unassociated.
TgaImage oiio_read(const fs::path& p) {
    OIIO::ImageSpec config;
    config.attribute("oiio:UnassociatedAlpha", 1);
    auto in = OIIO::ImageInput::open(p.string(), &config);
    if (!in) throw Error(p.string() + ": OpenImageIO cannot open it: " + OIIO::geterror());
    const OIIO::ImageSpec& spec = in->spec();
    TgaImage img;
    img.width = spec.width;
    img.height = spec.height;
    img.channels = spec.nchannels;
    std::vector<uint8_t> top_down(size_t(spec.width) * size_t(spec.height) * size_t(spec.nchannels));
    if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::UINT8, top_down.data()))
        throw Error(p.string() + ": OpenImageIO cannot read it: " + in->geterror());
    in->close();
    const size_t row = size_t(spec.width) * size_t(spec.nchannels);
    img.pixels.resize(top_down.size());
    for (int y = 0; y < spec.height; ++y)
        std::copy_n(top_down.data() + size_t(spec.height - 1 - y) * row, row, img.pixels.data() + size_t(y) * row);
    return img;
}

// What a TGA byte of value v must be: round(255 v), clamped (computed here, not by Atlas).
uint8_t byte_of(float v) { return uint8_t(std::lround(std::clamp(double(v), 0.0, 1.0) * 255.0)); }

// Values with long runs (flat regions, runs crossing rows) and noise.
Field3D runny_field(Vec3i res, int channels) {
    std::vector<std::string> names = {"r", "g", "b", "a"};
    names.resize(size_t(channels));
    return make_field3d(res, Box3d{{{0, 0, 0}}, {{1, 1, 1}}}, names, [](int x, int y, int z, int c) {
        if (x < 5 + z) return 0.25f * float(c);                                       // flat left part
        if (y % 3 == 0) return float((x / 7 + c) % 4) / 3.0f;                          // medium runs
        return unit_float(77, x, y, z, c);                                             // noise: raw packets
    });
}

std::vector<uint8_t> u8(const std::string& s) { return std::vector<uint8_t>(s.begin(), s.end()); }
std::string str(const std::vector<uint8_t>& v) { return std::string(v.begin(), v.end()); }

// A TGA header (18 bytes): type, w, h, bits per pixel, descriptor.
std::vector<uint8_t> tga_header(int type, int w, int h, int bits, int desc) {
    std::vector<uint8_t> b(18, 0);
    b[2] = uint8_t(type);
    b[12] = uint8_t(w & 255), b[13] = uint8_t(w >> 8), b[14] = uint8_t(h & 255), b[15] = uint8_t(h >> 8);
    b[16] = uint8_t(bits), b[17] = uint8_t(desc);
    return b;
}

} // namespace

TEST(TgaRle, EveryRleSliceReadsByOpenImageIOAsTheUncompressedOne) {
    TempDir dir;
    for (SlicePixels px : {SlicePixels::rgba, SlicePixels::rgb, SlicePixels::gray}) {
        const int ch = px == SlicePixels::rgba ? 4 : (px == SlicePixels::rgb ? 3 : 1);
        const Field3D f = runny_field({{37, 11, 4}}, ch);
        SliceOptions o;
        o.pixels = px;
        o.rle = true;
        const std::string tag = std::to_string(ch);
        const auto rle = write_tga_slices(f, dir.path(), "rle" + tag, o);
        o.rle = false;
        const auto raw = write_tga_slices(f, dir.path(), "raw" + tag, o);
        ASSERT_EQ(rle.size(), 4u);
        uint64_t rle_bytes = 0, raw_bytes = 0;
        for (size_t z = 0; z < rle.size(); ++z) {
            const std::string b = read_bytes(rle[z]);
            EXPECT_EQ(int(uint8_t(b[2])), ch == 1 ? 11 : 10) << rle[z];
            EXPECT_EQ(int(uint8_t(b[16])), 8 * ch) << rle[z];
            EXPECT_EQ(int(uint8_t(read_bytes(raw[z])[2])), ch == 1 ? 3 : 2) << raw[z];
            rle_bytes += fs::file_size(rle[z]);
            raw_bytes += fs::file_size(raw[z]);
            const TgaImage a = oiio_read(rle[z]), b2 = oiio_read(raw[z]);
            ASSERT_EQ(a.width, 37);
            ASSERT_EQ(a.height, 11);
            ASSERT_EQ(a.channels, ch);
            ASSERT_EQ(b2.channels, ch);
            EXPECT_EQ(a.pixels, b2.pixels) << rle[z] << " vs " << raw[z];
            // And both hold the field's bytes.
            for (int y = 0; y < 11; ++y)
                for (int x = 0; x < 37; ++x)
                    for (int c = 0; c < ch; ++c)
                        ASSERT_EQ(a.pixels[(size_t(y) * 37 + size_t(x)) * size_t(ch) + size_t(c)], byte_of(f.at(c, x, y, int(z))))
                            << rle[z] << " x " << x << " y " << y << " c " << c;
            // Atlas's own reader agrees with OpenImageIO.
            const TgaImage mine = read_tga(rle[z]);
            EXPECT_EQ(mine.channels, ch);
            EXPECT_EQ(mine.pixels, a.pixels);
        }
        EXPECT_LT(rle_bytes, raw_bytes) << ch << " channels";
    }
}

// 300 distinct pixels in a row need raw packets of 128, 128 and 44; 300 equal
// ones runs of 128, 128 and 44 (packets never span rows when Atlas writes).
TEST(TgaRle, RawPacketsOf128AndLongRunsAreSplitAndReadBack) {
    TempDir dir;
    TgaImage img;
    img.width = 300;
    img.height = 2;
    img.channels = 4;
    img.pixels.resize(300 * 2 * 4);
    for (int x = 0; x < 300; ++x) {
        for (int c = 0; c < 4; ++c) img.pixels[size_t(x) * 4 + size_t(c)] = uint8_t((x * 7 + c * 31 + (x >> 8) * 3) & 255); // row 0: all differ
        for (int c = 0; c < 4; ++c) img.pixels[(300 + size_t(x)) * 4 + size_t(c)] = uint8_t(9 + c);                          // row 1: one run
    }
    for (int x = 1; x < 300; ++x) ASSERT_NE(std::memcmp(&img.pixels[size_t(x) * 4], &img.pixels[size_t(x - 1) * 4], 4), 0);
    write_tga(dir / "p.tga", img, true);
    const std::vector<uint8_t> b = u8(read_bytes(dir / "p.tga"));
    size_t pos = 18;
    std::vector<int> heads;
    for (int n = 0; n < 600;) {
        const int head = b.at(pos);
        heads.push_back(head);
        const int count = (head & 0x7f) + 1;
        pos += 1 + size_t((head & 0x80) ? 4 : 4 * count);
        n += count;
    }
    const std::vector<int> expect = {127, 127, 43, 0x80 | 127, 0x80 | 127, 0x80 | 43};
    EXPECT_EQ(heads, expect);
    const TgaImage o = oiio_read(dir / "p.tga");
    EXPECT_EQ(o.pixels, img.pixels);
    EXPECT_EQ(read_tga(dir / "p.tga").pixels, img.pixels);
}

// Other writers let packets span rows (TGA 1.0 allowed it): a run from the end
// of row 0 into row 1, and a raw packet across rows, read as OpenImageIO reads them.
TEST(TgaRle, PacketsCrossingScanlinesReadLikeOpenImageIO) {
    TempDir dir;
    // 3x3, 24-bit, bottom-left origin. Rows in file order (bottom first).
    std::vector<uint8_t> b = tga_header(10, 3, 3, 24, 0);
    auto px = [&](uint8_t B, uint8_t G, uint8_t R) { b.push_back(B), b.push_back(G), b.push_back(R); };
    b.push_back(0x00); // raw 1: pixel 0
    px(1, 2, 3);
    b.push_back(0x83); // run of 4: pixels 1..4 (row 0 col 1 .. row 1 col 1)
    px(10, 20, 30);
    b.push_back(0x03); // raw 4: pixels 5..8 (row 1 col 2 .. row 2 col 2)
    px(40, 50, 60), px(41, 51, 61), px(42, 52, 62), px(43, 53, 63);
    write_bytes(dir / "x.tga", str(b));
    const TgaImage mine = read_tga(dir / "x.tga");
    const TgaImage other = oiio_read(dir / "x.tga");
    ASSERT_EQ(mine.channels, 3);
    EXPECT_EQ(mine.pixels, other.pixels);
    const std::vector<uint8_t> expect = {3, 2, 1, 30, 20, 10, 30, 20, 10, 30, 20, 10, 30, 20, 10, 60, 50, 40, 61, 51, 41, 62, 52, 42, 63, 53, 43};
    EXPECT_EQ(mine.pixels, expect);
    // Top-left origin: the first stored row is the top one.
    b[17] = 0x20;
    write_bytes(dir / "t.tga", str(b));
    EXPECT_EQ(read_tga(dir / "t.tga").pixels, oiio_read(dir / "t.tga").pixels);
    // Grey RLE (type 11), a run across rows.
    std::vector<uint8_t> g = tga_header(11, 2, 2, 8, 0);
    for (uint8_t v : {uint8_t(0x82), uint8_t(7), uint8_t(0x00), uint8_t(99)}) g.push_back(v);
    write_bytes(dir / "g.tga", str(g));
    const TgaImage gm = read_tga(dir / "g.tga");
    EXPECT_EQ(gm.channels, 1);
    EXPECT_EQ(gm.pixels, (std::vector<uint8_t>{7, 7, 7, 99}));
    EXPECT_EQ(gm.pixels, oiio_read(dir / "g.tga").pixels);
}

TEST(TgaRle, MalformedRleIsAClearErrorNamingTheFile) {
    TempDir dir;
    // Truncated raw packet: 4 pixels announced, 2 present.
    std::vector<uint8_t> a = tga_header(10, 4, 1, 32, 8);
    a.push_back(0x03);
    for (int i = 0; i < 8; ++i) a.push_back(uint8_t(i));
    write_bytes(dir / "cut.tga", str(a));
    expect_error_containing([&] { read_tga(dir / "cut.tga"); }, {"cut.tga", "truncated", "byte 18"});
    // Truncated run packet (header, no pixel).
    std::vector<uint8_t> r = tga_header(10, 4, 1, 32, 8);
    r.push_back(0x83);
    write_bytes(dir / "run.tga", str(r));
    expect_error_containing([&] { read_tga(dir / "run.tga"); }, {"run.tga", "truncated"});
    // Data ends before the image is complete.
    std::vector<uint8_t> e = tga_header(10, 4, 2, 32, 8);
    e.push_back(0x83);
    for (int i = 0; i < 4; ++i) e.push_back(uint8_t(i));
    write_bytes(dir / "short.tga", str(e));
    expect_error_containing([&] { read_tga(dir / "short.tga"); }, {"short.tga", "truncated", "4 of 8 pixels"});
    // A run past the end of the image.
    std::vector<uint8_t> o = tga_header(10, 2, 2, 32, 8);
    o.push_back(0x84); // 5 pixels into a 4-pixel image
    for (int i = 0; i < 4; ++i) o.push_back(uint8_t(i));
    write_bytes(dir / "over.tga", str(o));
    expect_error_containing([&] { read_tga(dir / "over.tga"); }, {"over.tga", "runs past the end", "4 pixels"});
    // In a stack, the slice is named.
    Field3D f({{2, 2, 3}}, 4, Box3d{{{0, 0, 0}}, {{1, 1, 1}}});
    write_tga_slices(f, dir.path(), "st");
    fs::copy_file(dir / "over.tga", dir / "st.002.tga", fs::copy_options::overwrite_existing);
    expect_error_containing([&] { read_tga_slices(dir / "st.001.tga", f.bounds()); }, {"st.002.tga", "runs past the end"});
    // Colour-mapped and odd depths are refused by name.
    write_bytes(dir / "cm.tga", str(tga_header(9, 2, 2, 8, 0)));
    expect_error_containing([&] { read_tga(dir / "cm.tga"); }, {"cm.tga", "colour-mapped"});
    write_bytes(dir / "d.tga", str(tga_header(2, 2, 2, 12, 0)));
    expect_error_containing([&] { read_tga(dir / "d.tga"); }, {"d.tga", "12 bits"});
}

// A file another writer (OpenImageIO) run-length encoded reads to its pixels.
TEST(TgaRle, ReadsRleWrittenByOpenImageIO) {
    TempDir dir;
    const int w = 23, h = 9;
    std::vector<uint8_t> top(size_t(w) * h * 4);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int c = 0; c < 4; ++c)
                top[(size_t(y) * w + size_t(x)) * 4 + size_t(c)] = uint8_t(x < 11 ? 40 * c : (x * 13 + y * 7 + c * 50) & 255);
    for (int y = 0; y < h; ++y) top[(size_t(y) * w) * 4 + 3] = 0; // A = 0 with colour, as the pack's modeling slices
    auto out = OIIO::ImageOutput::create("o.tga");
    ASSERT_TRUE(out);
    OIIO::ImageSpec spec(w, h, 4, OIIO::TypeDesc::UINT8);
    spec.attribute("compression", "rle");
    spec.attribute("oiio:UnassociatedAlpha", 1);
    ASSERT_TRUE(out->open((dir / "o.tga").string(), spec) && out->write_image(OIIO::TypeDesc::UINT8, top.data()) && out->close());
    const std::string b = read_bytes(dir / "o.tga");
    EXPECT_EQ(int(uint8_t(b[2])), 10) << "OpenImageIO wrote RLE";
    const TgaImage mine = read_tga(dir / "o.tga");
    ASSERT_EQ(mine.width, w);
    ASSERT_EQ(mine.channels, 4);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int c = 0; c < 4; ++c)
                ASSERT_EQ(mine.pixels[(size_t(y) * w + size_t(x)) * 4 + size_t(c)], top[(size_t(h - 1 - y) * w + size_t(x)) * 4 + size_t(c)])
                    << x << " " << y << " " << c;
}

TEST(TgaSlices, NubisNamingWritesAndFindsTheStack) {
    TempDir dir;
    Field3D f = runny_field({{5, 4, 12}}, 4);
    SliceOptions o;
    o.naming = SliceNaming::nubis;
    const auto files = write_tga_slices(f, dir.path(), "modeling_data", o);
    ASSERT_EQ(files.size(), 12u);
    std::vector<std::string> expect;
    for (int i = 0; i < 12; ++i) {
        EXPECT_EQ(files[size_t(i)], dir / ("modeling_data(" + std::to_string(i) + ").tga"));
        expect.push_back("modeling_data(" + std::to_string(i) + ").tga");
    }
    std::sort(expect.begin(), expect.end());
    EXPECT_EQ(names_in(dir.path()), expect);
    for (const char* p : {"modeling_data(0).tga", "modeling_data", "modeling_data(*).tga", "modeling_data(%d).tga"}) {
        const auto found = find_tga_slices(dir / p);
        ASSERT_EQ(found.size(), 12u) << p;
        EXPECT_EQ(found[10].filename(), "modeling_data(10).tga") << p; // numeric order, not "(1)", "(10)", "(11)", "(2)"
    }
    const Field3D g = read_tga_slices(dir / "modeling_data(0).tga", f.bounds(), 4);
    for (int c = 0; c < 4; ++c)
        for (size_t i = 0; i < f.voxel_count(); ++i) ASSERT_EQ(g.channel(c)[i], float(byte_of(f.channel(c)[i])) / 255.0f);
    // The generic reader (atlas compress / info) takes the pack's first slice as a stack too.
    const Value v = read_field_file(dir / "modeling_data(0).tga");
    ASSERT_TRUE(std::holds_alternative<Field3DPtr>(v));
    const Field3D& h = *std::get<Field3DPtr>(v);
    ASSERT_EQ(h.nz(), 12);
    for (size_t i = 0; i < f.voxel_count(); ++i) ASSERT_EQ(h.channel(1)[i], g.channel(1)[i]);
    expect_error_containing([&] { find_tga_slices(dir / "modeling_data(1).tga"); }, {"modeling_data(1).tga", "modeling_data(0).tga"});
    // A gap names the missing slice; both namings at once is ambiguous.
    fs::remove(dir / "modeling_data(4).tga");
    expect_error_containing([&] { find_tga_slices(dir / "modeling_data(0).tga"); }, {"modeling_data(4).tga", "missing"});
    TempDir two;
    write_tga_slices(f, two.path(), "s");
    write_tga_slices(f, two.path(), "s", o);
    expect_error_containing([&] { find_tga_slices(two / "s"); }, {"s.001.tga", "s(0).tga"});
    EXPECT_EQ(find_tga_slices(two / "s(0).tga").size(), 12u);
    EXPECT_EQ(find_tga_slices(two / "s.001.tga").size(), 12u);
}

TEST(TgaSlices, OutputOptionsNamingCompressionPixels) {
    TempDir dir;
    const Field3D f = runny_field({{9, 6, 3}}, 3);
    auto v = Field3DPtr(std::make_shared<Field3D>(f));
    auto files = write_value(v, dir / "pack" / "modeling_data", "tga-slices", {{"naming", "nubis"}, {"alpha", "0"}});
    ASSERT_EQ(files.size(), 3u);
    EXPECT_EQ(files[2], dir / "pack" / "modeling_data(2).tga");
    EXPECT_EQ(int(uint8_t(read_bytes(files[0])[2])), 10) << "RLE by default";
    files = write_value(v, dir / "raw", "tga-slices", {{"compression", "none"}});
    EXPECT_EQ(files[0], dir / "raw.001.tga");
    EXPECT_EQ(int(uint8_t(read_bytes(files[0])[2])), 2);
    files = write_value(v, dir / "grey", "tga-slices", {{"pixels", "gray"}, {"channels", "g"}});
    const TgaImage g = oiio_read(files[1]);
    ASSERT_EQ(g.channels, 1);
    for (int y = 0; y < 6; ++y)
        for (int x = 0; x < 9; ++x) ASSERT_EQ(g.pixels[size_t(y) * 9 + size_t(x)], byte_of(f.at(1, x, y, 1)));
    files = write_value(v, dir / "rgb", "tga-slices", {{"pixels", "rgb"}});
    EXPECT_EQ(oiio_read(files[0]).channels, 3);
    expect_error_containing([&] { write_value(v, dir / "x", "tga-slices", {{"naming", "pack"}}); }, {"naming", "atlas", "nubis", "'pack'"});
    expect_error_containing([&] { write_value(v, dir / "x", "tga-slices", {{"compression", "zip"}}); }, {"compression", "rle", "none"});
    expect_error_containing([&] { write_value(v, dir / "x", "tga-slices", {{"pixels", "la"}}); }, {"pixels", "rgba", "gray"});
    expect_error_containing([&] { write_value(v, dir / "x", "tga-slices", {{"pixels", "gray"}}); }, {"gray", "3", "channels"});
    expect_error_containing([&] { write_value(v, dir / "x", "tga-slices", {{"pixels", "rgb"}, {"alpha", "0"}}); }, {"alpha", "rgba"});
}

// A failed stack (NaN in the last slice) leaves no slice behind.
TEST(TgaSlices, FailedStackLeavesNothing) {
    TempDir dir;
    Field3D f({{3, 3, 4}}, 1, Box3d{{{0, 0, 0}}, {{1, 1, 1}}});
    f.at(0, 2, 2, 3) = std::numeric_limits<float>::quiet_NaN();
    expect_error_containing([&] { write_tga_slices(f, dir.path(), "n"); }, {"n.004.tga", "NaN"});
    EXPECT_TRUE(names_in(dir.path()).empty());
}

// 16-bit (A1R5G5B5) true colour: colour as OpenImageIO expands it (bit
// replication), the attribute bit as alpha 0 or 255.
TEST(TgaRle, SixteenBitTrueColourReadsLikeOpenImageIO) {
    TempDir dir;
    for (int type : {2, 10}) {
        std::vector<uint8_t> b = tga_header(type, 32, 2, 16, 1);
        for (int i = 0; i < 64; ++i) {
            if (type == 10) b.push_back(0x00); // one raw pixel per packet
            const int c = i % 32, v = (c << 10) | ((31 - c) << 5) | (c ^ 7) | (i % 3 ? 0x8000 : 0);
            b.push_back(uint8_t(v & 255)), b.push_back(uint8_t(v >> 8));
        }
        const fs::path p = dir / ("s" + std::to_string(type) + ".tga");
        write_bytes(p, str(b));
        const TgaImage mine = read_tga(p), other = oiio_read(p);
        ASSERT_EQ(mine.channels, 4);
        ASSERT_GE(other.channels, 3);
        for (size_t i = 0; i < 64; ++i) {
            for (int c = 0; c < 3; ++c) ASSERT_EQ(mine.pixels[i * 4 + size_t(c)], other.pixels[i * size_t(other.channels) + size_t(c)]) << p << " " << i;
            ASSERT_EQ(mine.pixels[i * 4 + 3], i % 3 ? 255 : 0);
        }
    }
}

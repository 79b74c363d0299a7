#include "atlas/io/image.h"

#include "io_test_util.h"

#include <OpenImageIO/imageio.h>

using namespace atlas;
using namespace atlas::io;
using namespace atlas::io::test;

namespace {

// Round trip through a file: every value lands within half a quantisation step
// (in field units) of the original; values outside the range clamp.
void check_round_trip(const fs::path& p, int channels, int bits, float lo, float hi) {
    std::vector<std::string> names = default_channel_names(channels);
    // Includes values outside [lo, hi] to exercise the clamp.
    const float span = hi - lo;
    Field2D f = make_field2d({{9, 7}}, Box2d{{{0, 0}}, {{9, 7}}}, names,
                             [&](int x, int y, int z, int c) { return unit_float(11, x, y, z, c, lo - 0.1f * span, hi + 0.1f * span); });
    ImageOptions o;
    o.bits = bits;
    o.range_min = lo;
    o.range_max = hi;
    write_image(f, p, o);
    Field2D g = read_image(p);
    ASSERT_EQ(g.resolution(), f.resolution());
    ASSERT_EQ(g.channels(), channels);
    const double full = std::ldexp(1.0, bits) - 1.0;
    const double step = span / full;
    for (int c = 0; c < channels; ++c)
        for (int y = 0; y < f.height(); ++y)
            for (int x = 0; x < f.width(); ++x) {
                const double expect = std::clamp(double(f.at(c, x, y)), double(lo), double(hi));
                const double got = lo + double(g.at(c, x, y)) * span; // read gives 0..1
                EXPECT_LE(std::fabs(got - expect), step / 2 + 1e-6 * span) << p << " channel " << c << " at " << x << "," << y;
            }
}

} // namespace

TEST(Image, Png8RoundTripWithinHalfStep) {
    TempDir dir;
    for (int ch = 1; ch <= 4; ++ch) check_round_trip(dir / ("a" + std::to_string(ch) + ".png"), ch, 8, 0.0f, 1.0f);
}

TEST(Image, Png16RoundTripWithinHalfStep) {
    TempDir dir;
    for (int ch = 1; ch <= 4; ++ch) check_round_trip(dir / ("b" + std::to_string(ch) + ".png"), ch, 16, -256.0f, 4096.0f);
}

TEST(Image, Tga8RoundTripWithinHalfStep) {
    TempDir dir;
    for (int ch : {1, 3, 4}) check_round_trip(dir / ("c" + std::to_string(ch) + ".tga"), ch, 8, -1.0f, 1.0f);
}

// Alpha must not be premultiplied on either side: colour under alpha 0 survives.
TEST(Image, AlphaIsNotPremultiplied) {
    TempDir dir;
    for (const char* name : {"a.png", "a.tga"}) {
        Field2D f({{2, 1}}, 4, Box2d{{{0, 0}}, {{2, 1}}});
        for (int c = 0; c < 3; ++c) f.at(c, 0, 0) = f.at(c, 1, 0) = 1.0f;
        f.at(3, 0, 0) = 0.0f;
        f.at(3, 1, 0) = 128.0f / 255.0f;
        write_image(f, dir / name);
        Field2D g = read_image(dir / name);
        for (int x = 0; x < 2; ++x)
            for (int c = 0; c < 3; ++c) EXPECT_EQ(g.at(c, x, 0), 1.0f) << name << " x " << x << " c " << c;
        EXPECT_EQ(g.at(3, 0, 0), 0.0f);
        EXPECT_NEAR(g.at(3, 1, 0), 128.0f / 255.0f, 1e-6f);
    }
}

// y = 0 of the field is the bottom row of the image (row h-1 in the file).
TEST(Image, FieldRowZeroIsImageBottomRow) {
    TempDir dir;
    Field2D f({{3, 4}}, 1, Box2d{{{0, 0}}, {{3, 4}}});
    for (int x = 0; x < 3; ++x) f.at(0, x, 0) = 1.0f; // bottom row white
    write_image(f, dir / "b.png");
    auto in = OIIO::ImageInput::open((dir / "b.png").string());
    ASSERT_TRUE(in);
    std::vector<uint8_t> px(12);
    ASSERT_TRUE(in->read_image(0, 0, 0, 1, OIIO::TypeDesc::UINT8, px.data()));
    in->close();
    for (int row = 0; row < 4; ++row)
        for (int x = 0; x < 3; ++x) EXPECT_EQ(px[size_t(row * 3 + x)], row == 3 ? 255 : 0) << "file row " << row;
    Field2D g = read_image(dir / "b.png");
    EXPECT_EQ(g.at(0, 1, 0), 1.0f);
    EXPECT_EQ(g.at(0, 1, 3), 0.0f);
}

TEST(Image, QuantisationRoundsToNearestAndClamps) {
    TempDir dir;
    Field2D f({{6, 1}}, 1, Box2d{{{0, 0}}, {{6, 1}}});
    const float vals[6] = {-5.0f, 0.0f, 0.5f / 255.0f - 1e-4f, 0.5f / 255.0f + 1e-4f, 254.6f / 255.0f, 7.0f};
    for (int x = 0; x < 6; ++x) f.at(0, x, 0) = vals[x];
    write_image(f, dir / "q.png");
    Field2D g = read_image(dir / "q.png");
    const int expect[6] = {0, 0, 0, 1, 255, 255};
    for (int x = 0; x < 6; ++x) EXPECT_EQ(std::lround(g.at(0, x, 0) * 255.0f), expect[x]) << x;
}

TEST(Image, CustomBoundsAreUsed) {
    TempDir dir;
    Field2D f({{2, 2}}, 1, Box2d{{{0, 0}}, {{2, 2}}});
    write_image(f, dir / "z.png");
    EXPECT_EQ(read_image(dir / "z.png").bounds(), (Box2d{{{0, 0}}, {{2, 2}}}));
    Box2d b{{{-8000, -8000}}, {{8000, 8000}}};
    EXPECT_EQ(read_image(dir / "z.png", b).bounds(), b);
    expect_error_containing([&] { read_image(dir / "z.png", Box2d{{{1, 0}}, {{0, 1}}}); }, {"z.png", "bounds"});
}

TEST(Image, NaNIsAnErrorNamingTheTexel) {
    TempDir dir;
    Field2D f({{4, 3}}, 2, Box2d{{{0, 0}}, {{4, 3}}}, {"u", "v"});
    f.at(1, 2, 1) = std::numeric_limits<float>::quiet_NaN();
    expect_error_containing([&] { write_image(f, dir / "n.png"); }, {"n.png", "NaN", "(2, 1)", "'v'"});
    EXPECT_FALSE(fs::exists(dir / "n.png"));
}

TEST(Image, InfinityClampsLikeAnyOutOfRangeValue) {
    TempDir dir;
    Field2D f({{2, 1}}, 1, Box2d{{{0, 0}}, {{2, 1}}});
    f.at(0, 0, 0) = -std::numeric_limits<float>::infinity();
    f.at(0, 1, 0) = std::numeric_limits<float>::infinity();
    write_image(f, dir / "i.png");
    Field2D g = read_image(dir / "i.png");
    EXPECT_EQ(g.at(0, 0, 0), 0.0f);
    EXPECT_EQ(g.at(0, 1, 0), 1.0f);
}

TEST(Image, BadOptionsAreErrors) {
    TempDir dir;
    Field2D f({{2, 2}}, 1, Box2d{{{0, 0}}, {{2, 2}}});
    ImageOptions o;
    o.bits = 12;
    expect_error_containing([&] { write_image(f, dir / "x.png", o); }, {"x.png", "bits", "12"});
    o.bits = 16;
    expect_error_containing([&] { write_image(f, dir / "x.tga", o); }, {"x.tga", "8"});
    o = {};
    o.range_min = 1;
    o.range_max = 1;
    expect_error_containing([&] { write_image(f, dir / "x.png", o); }, {"x.png", "range"});
    o.range_max = std::numeric_limits<float>::quiet_NaN();
    expect_error_containing([&] { write_image(f, dir / "x.png", o); }, {"x.png", "range"});
    Field2D five({{2, 2}}, 5, Box2d{{{0, 0}}, {{2, 2}}});
    expect_error_containing([&] { write_image(five, dir / "x.png"); }, {"x.png", "5"});
    expect_error_containing([&] { write_image(f, dir / "x.unknownext"); }, {"x.unknownext"});
}

// PNG is written with libpng (OpenImageIO is a module loaded on demand, so a
// process that writes only PNGs never loads it): the same file bytes as
// OpenImageIO 2.4's own PNG writer, checked here against it directly, for
// 1-4 channels at 8 and 16 bits; a different image (negative control)
// gives different bytes.
#include <OpenImageIO/filesystem.h>

#include <fstream>
#include <iterator>

TEST(Image, PngBytesAreOpenImageIOs) {
    TempDir dir;
    auto file_bytes = [](const fs::path& p) {
        std::ifstream in(p, std::ios::binary);
        return std::vector<unsigned char>(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    };
    for (int nc = 1; nc <= 4; ++nc)
        for (int bits : {8, 16}) {
            const int w = 37, h = 23;
            Field2D f = make_field2d({{w, h}}, Box2d{{{0, 0}}, {{double(w), double(h)}}}, default_channel_names(nc),
                                     [&](int x, int y, int z, int c) { return unit_float(5 + nc, x, y, z, c, -0.05f, 1.05f); });
            ImageOptions o;
            o.bits = bits;
            const fs::path mine = dir / ("m" + std::to_string(nc) + "_" + std::to_string(bits) + ".png");
            write_image(f, mine, o);
            // The same quantised pixels through OpenImageIO (file row order).
            const double full = std::ldexp(1.0, bits) - 1.0;
            std::vector<uint16_t> q(size_t(w) * h * nc);
            for (int y = 0; y < h; ++y)
                for (int x = 0; x < w; ++x)
                    for (int c = 0; c < nc; ++c)
                        q[(size_t(h - 1 - y) * w + x) * nc + c] = uint16_t(std::lround(std::clamp(double(f.at(c, x, y)), 0.0, 1.0) * full));
            std::vector<uint8_t> b(q.begin(), q.end());
            std::vector<unsigned char> encoded;
            OIIO::Filesystem::IOVecOutput proxy(encoded);
            auto out = OIIO::ImageOutput::create("x.png");
            ASSERT_TRUE(out && out->set_ioproxy(&proxy));
            OIIO::ImageSpec spec(w, h, nc, bits == 8 ? OIIO::TypeDesc::UINT8 : OIIO::TypeDesc::UINT16);
            spec.attribute("oiio:UnassociatedAlpha", 1);
            ASSERT_TRUE(out->open("x.png", spec));
            ASSERT_TRUE(bits == 8 ? out->write_image(OIIO::TypeDesc::UINT8, b.data()) : out->write_image(OIIO::TypeDesc::UINT16, q.data()));
            ASSERT_TRUE(out->close());
            EXPECT_EQ(file_bytes(mine), encoded) << nc << " channels, " << bits << " bits";
            // Negative control: one texel changed, other bytes.
            f.at(0, 3, 4) = f.at(0, 3, 4) > 0.5f ? 0.0f : 1.0f;
            write_image(f, mine, o);
            EXPECT_NE(file_bytes(mine), encoded);
        }
}

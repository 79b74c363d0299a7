#include "atlas/io/exr.h"

#include "io_test_util.h"

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfOutputFile.h>
#include <ImfInputFile.h>
#include <ImfIntAttribute.h>
#include <ImfRgbaFile.h>
#include <ImfStringAttribute.h>
#include <ImfVecAttribute.h>
#include <Imath/half.h>

#include <cstdlib>

using namespace atlas;
using namespace atlas::io;
using namespace atlas::io::test;

TEST(Exr, Field2DRoundTripIsBitExact) {
    TempDir dir;
    const Box2d b{{{-1500.25, 3.0}}, {{2500.5, 4099.0}}};
    // Channel names deliberately not in alphabetical order: the order must survive.
    Field2D f = make_field2d({{7, 5}}, b, {"density", "alpha", "zeta"}, [](int x, int y, int z, int c) { return awkward_float(1, x, y, z, c); });
    f.at(0, 0, 0) = 0.0f;
    f.at(1, 1, 0) = -0.0f;
    f.at(2, 6, 4) = std::numeric_limits<float>::denorm_min();
    write_exr(f, dir / "f.exr");
    Value v = read_exr(dir / "f.exr");
    ASSERT_TRUE(std::holds_alternative<Field2DPtr>(v));
    const Field2D& g = *std::get<Field2DPtr>(v);
    EXPECT_EQ(g.resolution(), f.resolution());
    EXPECT_EQ(g.bounds(), f.bounds());
    EXPECT_EQ(g.channel_names(), f.channel_names());
    for (int c = 0; c < f.channels(); ++c)
        for (size_t i = 0; i < f.voxel_count(); ++i) ASSERT_TRUE(same_bits(f.channel(c)[i], g.channel(c)[i])) << "channel " << c << " index " << i;
}

TEST(Exr, Field3DRoundTripIsBitExact) {
    TempDir dir;
    const Box3d b{{{-2048.0, -2048.0, 0.0}}, {{2048.0, 2048.0, 512.0}}};
    Field3D f = make_field3d({{6, 4, 3}}, b, {"r", "g"}, [](int x, int y, int z, int c) { return awkward_float(2, x, y, z, c); });
    ExrOptions o;
    o.channel_meaning = "r: density, g: type";
    write_exr(f, dir / "v.exr", o);
    Value v = read_exr(dir / "v.exr");
    ASSERT_TRUE(std::holds_alternative<Field3DPtr>(v));
    const Field3D& g = *std::get<Field3DPtr>(v);
    EXPECT_EQ(g.resolution(), f.resolution());
    EXPECT_EQ(g.bounds(), f.bounds());
    EXPECT_EQ(g.channel_names(), f.channel_names());
    for (int c = 0; c < f.channels(); ++c)
        for (size_t i = 0; i < f.voxel_count(); ++i) ASSERT_TRUE(same_bits(f.channel(c)[i], g.channel(c)[i]));
}

// compression: none (the SDF's option) writes an uncompressed file, checked with
// OpenEXR's own header, that reads back bit for bit, as ZIP (the default) does.
TEST(Exr, UncompressedRoundTripIsBitExactAndSaysSo) {
    TempDir dir;
    const Box3d b{{{0.0, 0.0, 0.0}}, {{64.0, 48.0, 40.0}}};
    Field3D f = make_field3d({{8, 6, 5}}, b, {"sdf"}, [](int x, int y, int z, int c) { return awkward_float(3, x, y, z, c); });
    ExrOptions o;
    o.compress = false;
    write_exr(f, dir / "raw.exr", o);
    write_exr(f, dir / "zip.exr");
    for (const char* name : {"raw.exr", "zip.exr"}) {
        Imf::InputFile in((dir / name).string().c_str());
        EXPECT_EQ(in.header().compression(), std::string(name) == "raw.exr" ? Imf::NO_COMPRESSION : Imf::ZIP_COMPRESSION) << name;
        const Value v = read_exr(dir / name);
        const Field3D& g = *std::get<Field3DPtr>(v);
        for (size_t i = 0; i < f.voxel_count(); ++i) ASSERT_TRUE(same_bits(f.channel(0)[i], g.channel(0)[i])) << name << " index " << i;
    }
}

// The documented layout, checked with OpenEXR directly: nx wide, ny*nz tall,
// slice z in rows [z*ny, (z+1)*ny), each slice's top row (y = ny-1) first,
// and the header attributes.
TEST(Exr, Field3DLayoutAndAttributes) {
    TempDir dir;
    const Box3d b{{{0.0, 10.0, 20.0}}, {{8.0, 13.0, 24.0}}};
    const int nx = 4, ny = 3, nz = 2;
    Field3D f = make_field3d({{nx, ny, nz}}, b, {"d"}, [](int x, int y, int z, int) { return float(x + 10 * y + 100 * z); });
    ExrOptions o;
    o.channel_meaning = "density";
    write_exr(f, dir / "v.exr", o);
    Imf::InputFile in((dir / "v.exr").string().c_str());
    const Imf::Header& h = in.header();
    const Imath::Box2i dw = h.dataWindow();
    ASSERT_EQ(dw.max.x - dw.min.x + 1, nx);
    ASSERT_EQ(dw.max.y - dw.min.y + 1, ny * nz);
    ASSERT_NE(h.findTypedAttribute<Imf::V3iAttribute>("atlas:resolution"), nullptr);
    EXPECT_EQ(h.typedAttribute<Imf::V3iAttribute>("atlas:resolution").value(), Imath::V3i(nx, ny, nz));
    EXPECT_EQ(h.typedAttribute<Imf::V3dAttribute>("atlas:bounds_min").value(), Imath::V3d(0, 10, 20));
    EXPECT_EQ(h.typedAttribute<Imf::V3dAttribute>("atlas:bounds_max").value(), Imath::V3d(8, 13, 24));
    EXPECT_EQ(h.typedAttribute<Imf::V3dAttribute>("atlas:voxel_size").value(), Imath::V3d(2, 1, 2));
    EXPECT_EQ(h.typedAttribute<Imf::StringAttribute>("atlas:channel_meaning").value(), "density");
    EXPECT_GE(h.typedAttribute<Imf::IntAttribute>("atlas:version").value(), 1);
    std::vector<float> px(size_t(nx * ny * nz));
    Imf::FrameBuffer fb;
    fb.insert("d", Imf::Slice(Imf::FLOAT, (char*)px.data(), sizeof(float), sizeof(float) * nx));
    in.setFrameBuffer(fb);
    in.readPixels(dw.min.y, dw.max.y);
    for (int z = 0; z < nz; ++z)
        for (int y = 0; y < ny; ++y)
            for (int x = 0; x < nx; ++x) EXPECT_EQ(px[size_t((z * ny + (ny - 1 - y)) * nx + x)], f.at(0, x, y, z));
}

// The writer works in strips of rows (a few MiB each): an image several strips
// tall, in float and in half, read back by OpenEXR itself, texel for texel.
TEST(Exr, Field3DTallerThanOneStripIsWhole) {
    TempDir dir;
    const int nx = 512, ny = 16, nz = 300; // 4800 rows of 2 channels: 3 strips of 1024 rows and a partial one
    Field3D f = make_field3d({{nx, ny, nz}}, Box3d{{{0, 0, 0}}, {{1, 1, 1}}}, {"a", "b"},
                             [](int x, int y, int z, int c) { return float((x + 3 * y + 5 * z + 7 * c) % 2048); });
    for (bool half : {false, true}) {
        ExrOptions o;
        o.half = half;
        const fs::path path = dir / (half ? "h.exr" : "f.exr");
        write_exr(f, path, o);
        Imf::InputFile in(path.string().c_str());
        const Imath::Box2i dw = in.header().dataWindow();
        ASSERT_EQ(dw.max.y - dw.min.y + 1, ny * nz);
        std::vector<float> a(size_t(nx) * ny * nz), b(a.size());
        Imf::FrameBuffer fb;
        fb.insert("a", Imf::Slice(Imf::FLOAT, (char*)a.data(), sizeof(float), sizeof(float) * nx));
        fb.insert("b", Imf::Slice(Imf::FLOAT, (char*)b.data(), sizeof(float), sizeof(float) * nx));
        in.setFrameBuffer(fb);
        in.readPixels(dw.min.y, dw.max.y);
        size_t wrong = 0;
        for (int z = 0; z < nz; ++z)
            for (int y = 0; y < ny; ++y)
                for (int x = 0; x < nx; ++x) {
                    const size_t i = size_t((z * ny + (ny - 1 - y)) * nx + x);
                    wrong += a[i] != f.at(0, x, y, z);
                    wrong += b[i] != f.at(1, x, y, z);
                }
        EXPECT_EQ(wrong, 0u) << (half ? "half" : "float");
    }
}

TEST(Exr, Field2DAttributesAreV2d) {
    TempDir dir;
    Field2D f({{4, 2}}, 1, Box2d{{{-4.0, 0.0}}, {{4.0, 1.0}}});
    write_exr(f, dir / "f.exr");
    Imf::InputFile in((dir / "f.exr").string().c_str());
    EXPECT_EQ(in.header().typedAttribute<Imf::V2dAttribute>("atlas:bounds_min").value(), Imath::V2d(-4, 0));
    EXPECT_EQ(in.header().typedAttribute<Imf::V2dAttribute>("atlas:bounds_max").value(), Imath::V2d(4, 1));
    EXPECT_EQ(in.header().typedAttribute<Imf::V2dAttribute>("atlas:voxel_size").value(), Imath::V2d(2, 0.5));
    EXPECT_EQ(in.header().findTypedAttribute<Imf::V3iAttribute>("atlas:resolution"), nullptr);
}

TEST(Exr, HalfRoundTripWithinHalfPrecision) {
    TempDir dir;
    Field3D f = make_field3d({{5, 4, 3}}, Box3d{{{0, 0, 0}}, {{1, 1, 1}}}, {"a", "b"},
                             [](int x, int y, int z, int c) { return unit_float(3, x, y, z, c, -1000.0f, 1000.0f); });
    ExrOptions o;
    o.half = true;
    write_exr(f, dir / "h.exr", o);
    {
        Imf::InputFile in((dir / "h.exr").string().c_str());
        EXPECT_EQ(in.header().channels().findChannel("a")->type, Imf::HALF);
    }
    const Field3DPtr g_ptr = std::get<Field3DPtr>(read_exr(dir / "h.exr"));
    const Field3D& g = *g_ptr;
    for (int c = 0; c < 2; ++c)
        for (size_t i = 0; i < f.voxel_count(); ++i) {
            const float a = f.channel(c)[i], r = g.channel(c)[i];
            // Half keeps 11 significant bits: relative error <= 2^-11 after rounding.
            EXPECT_LE(std::fabs(a - r), std::fabs(a) * (1.0f / 2048.0f) + 1e-7f) << a << " vs " << r;
            EXPECT_EQ(r, float(half(a)));
        }
}

TEST(Exr, PlainExrReadsAsField2DOverPixelBounds) {
    TempDir dir;
    const int w = 5, h = 3;
    std::vector<Imf::Rgba> px(size_t(w * h));
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) px[size_t(y * w + x)] = Imf::Rgba(half(float(x)), half(float(y)), half(0.5f), half(1.0f));
    {
        Imf::RgbaOutputFile out((dir / "plain.exr").string().c_str(), w, h, Imf::WRITE_RGBA);
        out.setFrameBuffer(px.data(), 1, size_t(w));
        out.writePixels(h);
    }
    Value v = read_exr(dir / "plain.exr");
    ASSERT_TRUE(std::holds_alternative<Field2DPtr>(v));
    const Field2D& f = *std::get<Field2DPtr>(v);
    EXPECT_EQ(f.resolution(), (Vec2i{{w, h}}));
    EXPECT_EQ(f.bounds(), (Box2d{{{0.0, 0.0}}, {{double(w), double(h)}}}));
    ASSERT_EQ(f.channels(), 4);
    const int r = f.find_channel("R"), g = f.find_channel("G");
    ASSERT_GE(r, 0);
    ASSERT_GE(g, 0);
    // File row 0 is the top: field y = h-1.
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            EXPECT_EQ(f.at(r, x, y), float(x));
            EXPECT_EQ(f.at(g, x, y), float(h - 1 - y));
        }
}

TEST(Exr, DataWindowNotAtOriginIsRead) {
    TempDir dir;
    Imath::Box2i display(Imath::V2i(0, 0), Imath::V2i(9, 9));
    Imath::Box2i data(Imath::V2i(3, 4), Imath::V2i(5, 5)); // 3x2 pixels
    Imf::Header hd(display, data);
    hd.channels().insert("Y", Imf::Channel(Imf::FLOAT));
    std::vector<float> px = {1, 2, 3, 4, 5, 6};
    {
        Imf::FrameBuffer fb;
        char* base = reinterpret_cast<char*>(px.data()) - (3 + 4 * 3) * sizeof(float);
        fb.insert("Y", Imf::Slice(Imf::FLOAT, base, sizeof(float), 3 * sizeof(float)));
        Imf::OutputFile out((dir / "dw.exr").string().c_str(), hd);
        out.setFrameBuffer(fb);
        out.writePixels(2);
    }
    const Field2DPtr f_ptr = std::get<Field2DPtr>(read_exr(dir / "dw.exr"));
    const Field2D& f = *f_ptr;
    ASSERT_EQ(f.resolution(), (Vec2i{{3, 2}}));
    EXPECT_EQ(f.at(0, 0, 1), 1.0f);
    EXPECT_EQ(f.at(0, 2, 1), 3.0f);
    EXPECT_EQ(f.at(0, 0, 0), 4.0f);
}

TEST(Exr, ResolutionAttributeThatDoesNotMatchIsAnError) {
    TempDir dir;
    Imf::Header hd(4, 6);
    hd.channels().insert("d", Imf::Channel(Imf::FLOAT));
    hd.insert("atlas:resolution", Imf::V3iAttribute(Imath::V3i(4, 4, 2))); // 4x8, not 4x6
    std::vector<float> px(24, 1.0f);
    {
        Imf::FrameBuffer fb;
        fb.insert("d", Imf::Slice(Imf::FLOAT, (char*)px.data(), sizeof(float), 4 * sizeof(float)));
        Imf::OutputFile out((dir / "bad.exr").string().c_str(), hd);
        out.setFrameBuffer(fb);
        out.writePixels(6);
    }
    expect_error_containing([&] { read_exr(dir / "bad.exr"); }, {"bad.exr", "atlas:resolution"});
}

TEST(Exr, WriteErrorsNameTheFile) {
    TempDir dir;
    Field2D f({{2, 2}}, 1, Box2d{{{0, 0}}, {{1, 1}}});
    expect_error_containing([&] { write_exr(f, dir / "no" / "such" / "dir" / "f.exr"); }, {"f.exr"});
}

// EXRs written by another tool (oiiotool): OpenEXR lists channels alphabetically
// (B, G, R), but standard names must come back in their conventional order.
namespace {
Field2D read_foreign(const fs::path& dir, const std::string& name, const std::string& oiiotool_args) {
    const fs::path p = dir / name;
    const std::string cmd = "oiiotool " + oiiotool_args + " -d float -o '" + p.string() + "' >/dev/null 2>&1";
    EXPECT_EQ(std::system(cmd.c_str()), 0) << cmd;
    Value v = read_exr(p);
    return *std::get<Field2DPtr>(v);
}
} // namespace

TEST(ExrForeign, RgbFromOiiotoolReadsAsRgb) {
    TempDir dir;
    const Field2D f = read_foreign(dir.path(), "rgb.exr", "--pattern constant:color=0.1,0.5,0.9 8x4 3");
    EXPECT_EQ(f.channel_names(), (std::vector<std::string>{"R", "G", "B"}));
    EXPECT_FLOAT_EQ(f.at(0, 3, 2), 0.1f);
    EXPECT_FLOAT_EQ(f.at(1, 3, 2), 0.5f);
    EXPECT_FLOAT_EQ(f.at(2, 3, 2), 0.9f);
}

TEST(ExrForeign, RgbaAndLayersAndVectors) {
    TempDir dir;
    const Field2D rgba = read_foreign(dir.path(), "rgba.exr", "--pattern constant:color=0.1,0.5,0.9,0.7 4x4 4");
    EXPECT_EQ(rgba.channel_names(), (std::vector<std::string>{"R", "G", "B", "A"}));
    EXPECT_FLOAT_EQ(rgba.at(3, 0, 0), 0.7f);
    const Field2D xyz = read_foreign(dir.path(), "xyz.exr", "--pattern constant:color=1,2,3 4x4 3 --chnames X,Y,Z");
    EXPECT_EQ(xyz.channel_names(), (std::vector<std::string>{"X", "Y", "Z"}));
    EXPECT_FLOAT_EQ(xyz.at(2, 1, 1), 3.0f);
    const Field2D ya = read_foreign(dir.path(), "ya.exr", "--pattern constant:color=0.25,0.75 4x4 2 --chnames Y,A");
    EXPECT_EQ(ya.channel_names(), (std::vector<std::string>{"Y", "A"}));
    EXPECT_FLOAT_EQ(ya.at(0, 1, 1), 0.25f);
    // Layers keep the file's order; channels inside each take the conventional order;
    // non-standard names follow alphabetically.
    const Field2D layered = read_foreign(dir.path(), "layers.exr",
                                         "--pattern constant:color=1,2,3,4,5,6 4x4 6 --chnames diffuse.R,diffuse.G,diffuse.B,normal.X,normal.Y,normal.Z");
    EXPECT_EQ(layered.channel_names(),
              (std::vector<std::string>{"diffuse.R", "diffuse.G", "diffuse.B", "normal.X", "normal.Y", "normal.Z"}));
    EXPECT_FLOAT_EQ(layered.at(4, 0, 0), 5.0f);
    const Field2D named = read_foreign(dir.path(), "named.exr", "--pattern constant:color=1,2,3 4x4 3 --chnames density,B,R");
    EXPECT_EQ(named.channel_names(), (std::vector<std::string>{"R", "B", "density"}));
    EXPECT_FLOAT_EQ(named.at(0, 0, 0), 3.0f);
}

TEST(ExrForeign, LuminanceChromaIsRefusedNamingTheChannel) {
    TempDir dir;
    const fs::path p = dir / "ryby.exr";
    ASSERT_EQ(std::system(("oiiotool --pattern constant:color=0.1,0.5,0.9 4x4 3 --chnames RY,Y,BY -d float -o '" + p.string() + "' >/dev/null 2>&1").c_str()), 0);
    try {
        read_exr(p);
        FAIL() << "an RY/BY image was accepted";
    } catch (const Error& e) {
        const std::string m = e.what();
        EXPECT_NE(m.find("ryby.exr"), std::string::npos) << m;
        EXPECT_NE(m.find("luminance/chroma"), std::string::npos) << m;
        EXPECT_TRUE(m.find("'BY'") != std::string::npos || m.find("'RY'") != std::string::npos) << m;
    }
}

#include "atlas/core/error.h"
#include "atlas/io/tga_slices.h"
#include "atlas/volume/nvdf.h"
#include "atlas/volume/shapes.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

using namespace atlas;
using namespace atlas::volume;

namespace {
const Box3d kBox{{{0, 0, 0}}, {{256, 192, 64}}};
Field3D sphere_sdf() {
    Shape s;
    s.a = {{128, 96, 32}};
    s.radius = 40;
    return shape_sdf(s, {{32, 24, 8}}, kBox);
}
struct TempDir {
    std::filesystem::path path = std::filesystem::temp_directory_path() / ("atlas_nvdf_" + std::to_string(::getpid()));
    bool keep = std::getenv("ATLAS_KEEP_TMP") != nullptr;
    TempDir() { std::filesystem::create_directories(path); }
    ~TempDir() { if (!keep) std::filesystem::remove_all(path); }
};
} // namespace

TEST(Nvdf, DimensionalProfileDefinition) {
    const Field3D sdf = sphere_sdf();
    DimensionalProfileOptions o;
    o.depth = 24;
    o.exponent = 2;
    const Field3D dp = dimensional_profile(sdf, o);
    for (size_t i = 0; i < sdf.voxel_count(); ++i) {
        const double s = sdf.channel(0)[i];
        const double e = s >= 0 ? 0 : std::pow(std::min(1.0, -s / 24), 2);
        ASSERT_NEAR(dp.channel(0)[i], e, 1e-6);
    }
    o.depth = 0;
    EXPECT_THROW(dimensional_profile(sdf, o), Error);
}

TEST(Nvdf, FieldDataEncodeDecode) {
    const Field3D sdf = sphere_sdf();
    const Field3D enc = encode_field_data(sdf);
    const Field3D dec = decode_field_data(enc);
    for (size_t i = 0; i < sdf.voxel_count(); ++i) {
        ASSERT_NEAR(enc.channel(0)[i], (sdf.channel(0)[i] + 256.0) / 4352.0, 1e-6);
        ASSERT_NEAR(dec.channel(0)[i], sdf.channel(0)[i], 1e-3);
    }
    EXPECT_THROW(encode_field_data(sdf, 10, 10), Error);
}

TEST(Nvdf, PackTgaLayoutsRoundTrip) {
    TempDir dir;
    const Field3D sdf = sphere_sdf();
    const Field3D dp = dimensional_profile(sdf);
    Field3D dt(sdf.resolution(), 1, kBox), ds(sdf.resolution(), 1, kBox);
    for (size_t i = 0; i < sdf.voxel_count(); ++i) {
        dt.channel(0)[i] = float(i % 7) / 6.0f;
        ds.channel(0)[i] = 0.25f + float(i % 3) / 4.0f;
    }
    const Field3D nvdf = assemble_modeling_nvdf(dp, dt, ds);
    const auto files = io::write_nubis_modeling_tga(nvdf, dir.path, "modeling", {io::SliceNaming::atlas, false});
    ASSERT_EQ(files.size(), 8u);
    // Raw layout, from the file's bytes: BGRA pixels after an 18-byte header, A = 0.
    {
        std::ifstream in(files[0], std::ios::binary);
        std::vector<unsigned char> b((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        ASSERT_EQ(b.size(), 18u + 32u * 24u * 4u + (b.size() - 18u - 32u * 24u * 4u)); // footer allowed
        ASSERT_EQ(b[2], 2);  // uncompressed true colour
        ASSERT_EQ(b[16], 32);
        const bool top_down = b[17] & 0x20;
        for (int y = 0; y < 24; ++y)
            for (int x = 0; x < 32; ++x) {
                const int row = top_down ? 23 - y : y;
                const unsigned char* p = &b[18 + (size_t(row) * 32 + size_t(x)) * 4];
                ASSERT_EQ(p[2], std::lround(double(nvdf.at(0, x, y, 0)) * 255.0)); // R
                ASSERT_EQ(p[1], std::lround(double(nvdf.at(1, x, y, 0)) * 255.0)); // G
                ASSERT_EQ(p[0], std::lround(double(nvdf.at(2, x, y, 0)) * 255.0)); // B
                ASSERT_EQ(p[3], 0);                                       // A
            }
    }
    const Field3D back = io::read_nubis_modeling_tga(files[0], kBox);
    EXPECT_EQ(back.channel_names(), nvdf.channel_names());
    for (size_t i = 0; i < back.voxel_count(); ++i)
        for (int c = 0; c < 3; ++c) ASSERT_NEAR(back.channel(c)[i], nvdf.channel(c)[i], 0.5 / 255 + 1e-6);

    const auto fd = io::write_nubis_field_data_tga(sdf, dir.path, "field");
    const Field3D fraw = io::read_tga_slices(fd[0], kBox, 4);
    const Field3D fback = io::read_nubis_field_data_tga(fd[0], kBox);
    for (size_t i = 0; i < fraw.voxel_count(); ++i) {
        // d = R/255 * 4352 - 256 with R the byte; G = B = 0, A = 255.
        const double r_byte = std::round(fraw.channel(0)[i] * 255.0);
        ASSERT_NEAR(r_byte / 255 * 4352 - 256, sdf.channel(0)[i], 4352.0 / 255 / 2 + 1e-3);
        ASSERT_NEAR(fback.channel(0)[i], r_byte / 255 * 4352 - 256, 1e-2);
        ASSERT_EQ(fraw.channel(1)[i], 0.0f);
        ASSERT_EQ(fraw.channel(2)[i], 0.0f);
        ASSERT_EQ(fraw.channel(3)[i], 1.0f);
    }
}

TEST(Nvdf, PackVdbRoundTrip) {
    TempDir dir;
    const Field3D sdf = sphere_sdf();
    const Field3D dp = dimensional_profile(sdf);
    Field3D dt(sdf.resolution(), 1, kBox), ds(sdf.resolution(), 1, kBox);
    std::fill(ds.channel(0).begin(), ds.channel(0).end(), 1.0f);
    const Field3D nvdf = assemble_modeling_nvdf(dp, dt, ds);
    io::write_nubis_vdb(nvdf, sdf, dir.path / "cloud.vdb");
    const Field3D back = io::read_nubis_vdb(dir.path / "cloud.vdb");
    ASSERT_EQ(back.channels(), 4);
    EXPECT_EQ(back.channel_name(3), "sdf");
    ASSERT_EQ(back.resolution(), sdf.resolution());
    for (size_t i = 0; i < sdf.voxel_count(); ++i) {
        for (int c = 0; c < 3; ++c) ASSERT_EQ(back.channel(c)[i], nvdf.channel(c)[i]);
        ASSERT_EQ(back.channel(3)[i], sdf.channel(0)[i]);
    }
    Field3D wrong({{4, 4, 4}}, 1, kBox);
    EXPECT_THROW(assemble_modeling_nvdf(dp, wrong, ds), Error);
}

// The pack's own naming and RLE (the default encoding): the same values come back.
TEST(Nvdf, PackTgaNubisNamingAndRle) {
    TempDir dir;
    const Field3D sdf = sphere_sdf();
    Field3D dt(sdf.resolution(), 1, kBox), ds(sdf.resolution(), 1, kBox);
    for (size_t i = 0; i < sdf.voxel_count(); ++i) {
        dt.channel(0)[i] = float(i % 5) / 4.0f;
        ds.channel(0)[i] = 0.5f;
    }
    const Field3D nvdf = assemble_modeling_nvdf(dimensional_profile(sdf), dt, ds);
    const auto files = io::write_nubis_modeling_tga(nvdf, dir.path, "modeling_data", {io::SliceNaming::nubis, true});
    ASSERT_EQ(files.size(), 8u);
    EXPECT_EQ(files[7].filename(), "modeling_data(7).tga");
    std::ifstream in(files[3], std::ios::binary);
    std::vector<unsigned char> b((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    ASSERT_GE(b.size(), 18u);
    EXPECT_EQ(b[2], 10); // RLE true colour
    EXPECT_EQ(b[16], 32);
    const Field3D back = io::read_nubis_modeling_tga(dir.path / "modeling_data(0).tga", kBox);
    for (size_t i = 0; i < back.voxel_count(); ++i)
        for (int c = 0; c < 3; ++c) ASSERT_NEAR(back.channel(c)[i], nvdf.channel(c)[i], 0.5 / 255 + 1e-6);
    const auto fd = io::write_nubis_field_data_tga(sdf, dir.path, "field_data", {io::SliceNaming::nubis, true});
    const Field3D fback = io::read_nubis_field_data_tga(dir.path / "field_data", kBox);
    for (size_t i = 0; i < fback.voxel_count(); ++i) ASSERT_NEAR(fback.channel(0)[i], sdf.channel(0)[i], 4352.0 / 255 / 2 + 1e-2);
}

TEST(Nvdf, AssembleTakesEachInputsChannel) {
    const Field3D sdf = sphere_sdf();
    const Field3D dp = dimensional_profile(sdf);
    Field3D rgba(sdf.resolution(), 4, kBox);
    for (size_t i = 0; i < sdf.voxel_count(); ++i)
        for (int c = 0; c < 4; ++c) rgba.channel(c)[i] = float((i + size_t(c) * 3) % 11) / 10.0f;
    ModelingChannels mc;
    mc.detail_type = 1;
    mc.density_scale = 2;
    const Field3D m = assemble_modeling_nvdf(dp, rgba, rgba, nullptr, mc);
    for (size_t i = 0; i < sdf.voxel_count(); ++i) {
        ASSERT_EQ(m.channel(1)[i], rgba.channel(1)[i]);
        ASSERT_EQ(m.channel(2)[i], rgba.channel(2)[i]);
    }
    mc.density_scale = 4;
    try {
        assemble_modeling_nvdf(dp, rgba, rgba, nullptr, mc);
        FAIL() << "expected an error";
    } catch (const Error& e) {
        const std::string w = e.what();
        EXPECT_NE(w.find("density_scale"), std::string::npos) << w;
        EXPECT_NE(w.find("channel 4"), std::string::npos) << w;
    }
}

namespace {
// An NVDF-like set of a sphere: profile 1 inside, sdf its exact distance (brute force), scale s.
Field3D sphere_set(double cx, double r, float scale) {
    Field3D f({{16, 8, 8}}, 2, Box3d{{{0, 0, 0}}, {{16, 8, 8}}}, {"dimensional_profile", "sdf"});
    for (int z = 0; z < 8; ++z)
        for (int y = 0; y < 8; ++y)
            for (int x = 0; x < 16; ++x) {
                const double d = std::sqrt((x + 0.5 - cx) * (x + 0.5 - cx) + (y + 0.5 - 4) * (y + 0.5 - 4) + (z + 0.5 - 4) * (z + 0.5 - 4)) - r;
                f.at(0, x, y, z) = d < 0 ? scale : 0.0f;
                f.at(1, x, y, z) = float(d);
            }
    return f;
}
} // namespace

TEST(NvdfBlend, ChannelsLerpAndTheSdfIsTheUnionsExactDistance) {
    const Field3D a = sphere_set(4, 3, 1.0f), b = sphere_set(12, 2.5, 0.5f);
    const Field3D m = volume::blend_nvdf(a, b, 0.25);
    ASSERT_EQ(m.channels(), 2);
    EXPECT_EQ(m.channel_name(1), "sdf");
    for (size_t i = 0; i < m.voxel_count(); ++i) {
        EXPECT_FLOAT_EQ(m.channel(0)[i], a.channel(0)[i] * 0.75f + b.channel(0)[i] * 0.25f);
        // The distance to the union of the two spheres, brute force: the smaller one. Never more:
        // the blended cloud lies where either cloud does, and skipping must not step over it.
        EXPECT_EQ(m.channel(1)[i], std::min(a.channel(1)[i], b.channel(1)[i]));
        if (m.channel(0)[i] > 0) {
            EXPECT_LT(m.channel(1)[i], 0.0f) << "density outside the blended SDF at voxel " << i;
        }
    }
    // At the ends, the sets themselves (sdf included), and t is clamped.
    const Field3D at0 = volume::blend_nvdf(a, b, 0), at1 = volume::blend_nvdf(a, b, 1), past = volume::blend_nvdf(a, b, 7);
    for (size_t i = 0; i < a.voxel_count(); ++i) {
        EXPECT_EQ(at0.channel(1)[i], a.channel(1)[i]);
        EXPECT_EQ(at1.channel(1)[i], b.channel(1)[i]);
        EXPECT_EQ(past.channel(0)[i], b.channel(0)[i]);
    }
}

TEST(NvdfBlend, DifferentGridsOrChannelsAreClearErrors) {
    const Field3D a = sphere_set(4, 3, 1.0f);
    Field3D moved({{16, 8, 8}}, 2, Box3d{{{1, 0, 0}}, {{17, 8, 8}}}, {"dimensional_profile", "sdf"});
    try {
        volume::blend_nvdf(a, moved, 0.5);
        ADD_FAILURE() << "different bounds were blended";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("must share one grid"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("[1, 0, 0]"), std::string::npos) << e.what();
    }
    Field3D renamed({{16, 8, 8}}, 2, Box3d{{{0, 0, 0}}, {{16, 8, 8}}}, {"dimensional_profile", "distance"});
    EXPECT_THROW(volume::blend_nvdf(a, renamed, 0.5), Error);
    EXPECT_THROW(volume::blend_nvdf(a, a, std::nan("")), Error);
}

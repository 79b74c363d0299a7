// OpenImageIO's DDS reader opens Atlas's BC1 and BC4 files and agrees with Atlas's
// decoder (OIIO 2.4 decodes through squish: the Tool8 model).
#include "atlas/compress/texture.h"
#include "atlas/io/dds_file.h"

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <filesystem>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <unistd.h>

namespace atlas::compress {
namespace fs = std::filesystem;
using io::compress_to_dds;
using io::read_dds;
using io::read_dds_file;
using io::verify_dds;
namespace {

Field3D smooth_rgb(int nx, int ny) {
    Field3D f(Vec3i{{nx, ny, 1}}, 3, Box3d{{{0, 0, 0}}, {{1, 1, 1}}});
    for (int y = 0; y < ny; ++y)
        for (int x = 0; x < nx; ++x)
            for (int c = 0; c < 3; ++c)
                f.at(c, x, y, 0) = float(0.5 + 0.45 * std::sin(0.21 * x * (c + 1) + 0.13 * y + c));
    return f;
}

// OIIO 2.4 decodes to 8 bits with its own rounding, which none of the models
// reproduces bit-exactly: it agrees with Tool8Round within one 8-bit step.
void compare_with_oiio(Format fmt, int nx, int ny, double tolerance) {
    const fs::path dir = fs::temp_directory_path() / ("atlas_oiio_dds_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    const fs::path p = dir / (std::string(format_name(fmt)) + ".dds");
    CompressOptions o;
    o.format = fmt;
    o.value_range = std::make_pair(0.0f, 1.0f);
    compress_to_dds(smooth_rgb(nx, ny), p, o);
    DdsTexture tex = read_dds_file(p);
    const Field3D ours = decode_texture(tex, nullptr, Decoder::Tool8Round);
    const Field3D ref = decode_texture(tex, nullptr, Decoder::Reference);

    auto in = OIIO::ImageInput::open(p.string());
    ASSERT_TRUE(in) << OIIO::geterror();
    const OIIO::ImageSpec& spec = in->spec();
    ASSERT_EQ(spec.width, nx);
    ASSERT_EQ(spec.height, ny);
    std::vector<float> px(size_t(nx) * size_t(ny) * size_t(spec.nchannels));
    ASSERT_TRUE(in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, px.data()));
    in->close();
    double worst = 0, worst_round = 0;
    // OIIO's row `row` (counted from the top) is field row ny - 1 - row (fields are y-up).
    for (int row = 0; row < ny; ++row)
        for (int x = 0; x < nx; ++x)
            for (int c = 0; c < ours.channels(); ++c) {
                const int y = ny - 1 - row;
                const float theirs = px[(size_t(row) * size_t(nx) + size_t(x)) * size_t(spec.nchannels) + size_t(c)];
                if (std::fabs(theirs - ours.at(c, x, y, 0)) > 0.5 / 255 && worst <= 0.5 / 255)
                    std::printf("first diff at %d %d c%d: oiio %.2f tool8 %.2f ref %.2f\n", x, y, c, theirs * 255, ours.at(c, x, y, 0) * 255, ref.at(c, x, y, 0) * 255);
                worst = std::max(worst, double(std::fabs(theirs - ours.at(c, x, y, 0))));
                worst_round = std::max(worst_round, double(std::fabs(theirs - std::nearbyint(ref.at(c, x, y, 0) * 255.0f) / 255.0f)));
            }
    std::printf("%s: OIIO vs tool8 %.3f/255, vs rounded reference %.3f/255\n", format_name(fmt), worst * 255, worst_round * 255);
    EXPECT_LE(worst, tolerance) << format_name(fmt) << ": OIIO and the Tool8 model differ by " << worst * 255 << "/255";
}

// The picture's top row (field row ny - 1: fields are y-up, as PNG/EXR/TGA output
// shows them) must be OpenImageIO's row 0, for every format and for array and
// volume slices: a DDS looks like the PNG of the same field in any viewer.
Field3D top_bright(int nx, int ny, int nz) {
    Field3D f(Vec3i{{nx, ny, nz}}, 3, Box3d{{{0, 0, 0}}, {{1, 1, 1}}});
    for (int z = 0; z < nz; ++z)
        for (int y = 0; y < ny; ++y)
            for (int x = 0; x < nx; ++x) {
                f.at(0, x, y, z) = float(y) / float(ny - 1);       // red: 0 at the bottom, 1 at the top
                f.at(1, x, y, z) = float(x) / float(nx - 1);       // green: 0 at the left
                f.at(2, x, y, z) = y >= ny - 4 && x < 4 ? 1.0f : 0.0f; // blue: a mark in the top-left corner
            }
    return f;
}

std::vector<float> oiio_pixels(const fs::path& p, OIIO::ImageSpec& spec) {
    auto in = OIIO::ImageInput::open(p.string());
    EXPECT_TRUE(in) << OIIO::geterror();
    if (!in) return {};
    spec = in->spec();
    std::vector<float> px(size_t(spec.width) * size_t(spec.height) * size_t(spec.nchannels));
    EXPECT_TRUE(in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, px.data())) << in->geterror();
    in->close();
    return px;
}

// OIIO 2.4 reads 2D BC1 (legacy header) and BC4 DDS files, not volumes, arrays or
// DX10 uncompressed formats; those are checked on the raw bytes below.
TEST(OiioDds, RowsMatchPngOrientation) {
    const fs::path dir = fs::temp_directory_path() / ("atlas_oiio_rows_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    const int nx = 16, ny = 12;
    for (Format fmt : {Format::Bc1, Format::Bc4}) {
        for (int nz : {1}) {
            const fs::path p = dir / (std::string(format_name(fmt)) + std::to_string(nz) + ".dds");
            CompressOptions o;
            o.format = fmt;
            o.value_range = std::make_pair(0.0f, 1.0f);
            compress_to_dds(top_bright(nx, ny, nz), p, o);
            OIIO::ImageSpec spec;
            const std::vector<float> px = oiio_pixels(p, spec);
            ASSERT_EQ(spec.width, nx);
            ASSERT_EQ(spec.height, ny);
            auto at = [&](int x, int row, int c) { return px[(size_t(row) * size_t(nx) + size_t(x)) * size_t(spec.nchannels) + size_t(c)]; };
            for (int x = 0; x < nx; ++x) {
                EXPECT_GT(at(x, 0, 0), 0.9f) << format_name(fmt) << " nz " << nz << ": OIIO's top row is not the field's top";
                EXPECT_LT(at(x, ny - 1, 0), 0.1f) << format_name(fmt) << " nz " << nz << ": OIIO's bottom row is not the field's bottom";
            }
            if (fmt != Format::Bc4) { // BC4 stores red only
                EXPECT_LT(at(0, 0, 1), 0.1f) << format_name(fmt) << ": left column";
                EXPECT_GT(at(nx - 1, 0, 1), 0.9f) << format_name(fmt) << ": right column";
                EXPECT_GT(at(1, 1, 2), 0.8f) << format_name(fmt) << ": the top-left mark";
                EXPECT_LT(at(1, ny - 2, 2), 0.2f) << format_name(fmt) << ": no mark at the bottom-left";
            }
            // Atlas's own decode flips back: the field it returns is the source (y-up).
            const Field3D back = read_dds(p);
            EXPECT_NEAR(back.at(0, 3, ny - 1, nz - 1), 1.0f, 0.1f);
            EXPECT_NEAR(back.at(0, 3, 0, nz - 1), 0.0f, 0.1f);
        }
    }
}

// A volume's slices and every mip level store rows top-down too: read from the
// bytes as the DDS specification lays them out (R8G8B8A8, DX10 header of 148 bytes).
TEST(OiioDds, VolumeSlicesAndMipsStoreRowsTopDown) {
    const fs::path dir = fs::temp_directory_path() / ("atlas_oiio_vol_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    const int nx = 16, ny = 12, nz = 4;
    const fs::path p = dir / "vol.dds";
    CompressOptions o;
    o.format = Format::Rgba8;
    o.value_range = std::make_pair(0.0f, 1.0f);
    o.mip_levels = 2;
    compress_to_dds(top_bright(nx, ny, nz), p, o);
    const std::vector<uint8_t> b = [&] {
        std::ifstream f(p, std::ios::binary);
        return std::vector<uint8_t>((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
    }();
    ASSERT_EQ(b.size(), size_t(148 + 4 * (nx * ny * nz + (nx / 2) * (ny / 2) * (nz / 2))));
    auto red = [&](size_t level_offset, int w, int h, int x, int row, int z) {
        return b[148 + level_offset + ((size_t(z) * size_t(h) + size_t(row)) * size_t(w) + size_t(x)) * 4];
    };
    for (int z = 0; z < nz; ++z) {
        EXPECT_EQ(red(0, nx, ny, 5, 0, z), 255) << "slice " << z << ": first stored row is the top";
        EXPECT_EQ(red(0, nx, ny, 5, ny - 1, z), 0) << "slice " << z;
    }
    const size_t mip1 = size_t(4) * size_t(nx * ny * nz);
    EXPECT_GT(red(mip1, nx / 2, ny / 2, 2, 0, 0), 200) << "mip 1: first stored row is the top";
    EXPECT_LT(red(mip1, nx / 2, ny / 2, 2, ny / 2 - 1, 0), 50);
}

TEST(OiioDds, Bc1AgreesWithTool8RoundDecoder) { compare_with_oiio(Format::Bc1, 32, 20, 1.0001 / 255.0); }

// BC1 given --max-error, as OpenImageIO decodes it: within the bound everywhere (the
// bound covers the Tool8Round model, which OIIO matches within one 8-bit step), and the
// room under the bound buys a lower RMSE than the unbounded encode's. A noisy colour
// field, so blocks do not lie on one line in RGB.
TEST(OiioDds, Bc1BoundHoldsUnderOiioAndLowersItsRmse) {
    const fs::path dir = fs::temp_directory_path() / ("atlas_oiio_bound_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    const int nx = 64, ny = 48;
    Field3D f(Vec3i{{nx, ny, 1}}, 3, Box3d{{{0, 0, 0}}, {{1, 1, 1}}});
    for (int y = 0; y < ny; ++y)
        for (int x = 0; x < nx; ++x)
            for (int c = 0; c < 3; ++c) {
                const uint32_t h = (uint32_t(x) * 73856093u) ^ (uint32_t(y) * 19349663u) ^ (uint32_t(c) * 83492791u);
                f.at(c, x, y, 0) = float(0.5 + 0.3 * std::sin(0.3 * x + 1.7 * c) * std::cos(0.2 * y) + 0.06 * double(h % 1000u) / 1000.0);
            }
    auto oiio_errors = [&](const fs::path& p, double& max_err, double& rmse) {
        OIIO::ImageSpec spec;
        const std::vector<float> px = oiio_pixels(p, spec);
        ASSERT_EQ(spec.width, nx);
        double sq = 0;
        max_err = 0;
        for (int row = 0; row < ny; ++row)
            for (int x = 0; x < nx; ++x)
                for (int c = 0; c < 3; ++c) {
                    const double d = px[(size_t(row) * size_t(nx) + size_t(x)) * size_t(spec.nchannels) + size_t(c)] - f.at(c, x, ny - 1 - row, 0);
                    max_err = std::max(max_err, std::fabs(d));
                    sq += d * d;
                }
        rmse = std::sqrt(sq / (3.0 * nx * ny));
    };
    CompressOptions o;
    o.format = Format::Bc1;
    o.value_range = std::make_pair(0.0f, 1.0f);
    o.decoders = decoder_bit(Decoder::Reference) | decoder_bit(Decoder::Tool8Round);
    compress_to_dds(f, dir / "free.dds", o);
    double free_max = 0, free_rmse = 0;
    oiio_errors(dir / "free.dds", free_max, free_rmse);
    o.max_error = 0.12f;
    compress_to_dds(f, dir / "bound.dds", o); // throws if a block misses the bound
    double bound_max = 0, bound_rmse = 0;
    oiio_errors(dir / "bound.dds", bound_max, bound_rmse);
    std::printf("BC1 via OIIO: unbounded max %.2f/255 RMSE %.3f/255; --max-error %.1f/255: max %.2f/255 RMSE %.3f/255\n", free_max * 255,
                free_rmse * 255, double(*o.max_error) * 255, bound_max * 255, bound_rmse * 255);
    EXPECT_LE(bound_max, double(*o.max_error) + 1.0001 / 255.0);
    EXPECT_LT(free_max, double(*o.max_error)) << "the bound must leave room over the unbounded max error";
    EXPECT_LT(bound_rmse, 0.97 * free_rmse);
    fs::remove_all(dir);
}
TEST(OiioDds, Bc4AgreesWithTool8RoundDecoder) { compare_with_oiio(Format::Bc4, 32, 20, 1.0001 / 255.0); }

} // namespace
} // namespace atlas::compress

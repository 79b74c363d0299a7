// Texture API: DDS round trips (2D, arrays, volumes with mips), one-sided SDF fields
// under every decoder, bounds and their reports, determinism, bad input.
#include "atlas/compress/texture.h"
#include "atlas/io/dds_file.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>

namespace atlas::compress {
namespace fs = std::filesystem;
using io::compress_to_dds;
using io::read_dds;
using io::read_dds_file;
using io::verify_dds;
namespace {

fs::path temp_dir() {
    fs::path d = fs::temp_directory_path() / ("atlas_compress_test_" + std::to_string(::getpid()));
    fs::create_directories(d);
    return d;
}

// SDF-like fields: distance to a sphere, a linear ramp, and a kinked (abs) field, in metres.
Field3D sdf_field(int nx, int ny, int nz, int kind) {
    Field3D f(Vec3i{{nx, ny, nz}}, 1, Box3d{{{0, 0, 0}}, {{double(nx), double(ny), double(nz)}}}, {"distance"});
    for (int z = 0; z < nz; ++z)
        for (int y = 0; y < ny; ++y)
            for (int x = 0; x < nx; ++x) {
                double v;
                if (kind == 0) v = std::sqrt((x - nx * 0.4) * (x - nx * 0.4) + (y - ny * 0.55) * (y - ny * 0.55) + (z - nz * 0.5) * (z - nz * 0.5)) * 8.0 - 64.0;
                else if (kind == 1) v = 3.7 * x + 1.3 * y - 2.1 * z;
                else v = std::fabs(x - nx * 0.37) * 8.0 + std::fabs(y - ny * 0.61) * 2.0 + z - 40.0;
                f.at(0, x, y, z) = float(v);
            }
    return f;
}

TEST(Texture, OneSidedSdfHoldsForEveryDecoderBc4AndBc1Scalar) {
    for (Format fmt : {Format::Bc4, Format::Bc1Scalar, Format::R8, Format::R16F}) {
        for (int kind = 0; kind < 3; ++kind) {
            CompressOptions o;
            o.format = fmt;
            o.one_sided_below = true;
            o.decoders = kAllDecoders;
            EncodedTexture e = encode_texture(sdf_field(32, 32, 4, kind), o);
            ASSERT_TRUE(e.report.blocks_over_bound.empty()) << format_name(fmt);
            // Uncompressed formats decode alike under every model (checked below), so they
            // are verified once; BC formats once per model.
            ASSERT_EQ(e.report.per_decoder.size(), is_block_compressed(dxgi_format(fmt)) ? size_t(kDecoderCount) : size_t(1));
            EXPECT_EQ(e.manifest.decoders.size(), size_t(kDecoderCount)) << "the manifest lists every model the bound covers";
            if (!is_block_compressed(dxgi_format(fmt))) {
                const Field3D ref = decode_texture(e.dds, &e.manifest, Decoder::Reference);
                for (int d = 0; d < kDecoderCount; ++d) {
                    const Field3D other = decode_texture(e.dds, &e.manifest, static_cast<Decoder>(d));
                    for (size_t i = 0; i < ref.voxel_count(); ++i)
                        ASSERT_EQ(ref.channel(0)[i], other.channel(0)[i]) << format_name(fmt) << " " << decoder_name(static_cast<Decoder>(d));
                }
            }
            for (const DecoderStats& d : e.report.per_decoder) {
                EXPECT_LE(d.max_over, 0.0) << format_name(fmt) << " kind " << kind << " " << decoder_name(d.decoder);
                EXPECT_EQ(d.one_sided_violations, 0u);
                EXPECT_GE(d.mean_under, 0.0);
            }
            std::printf("one-sided %-10s field %d: range %.1f m, mean under-estimate (reference) %.5f m, max error %.5f m\n",
                        format_name(fmt), kind, double(e.report.value_range.second - e.report.value_range.first),
                        e.report.per_decoder[0].mean_under, e.report.bound_max_error);
        }
    }
}

TEST(Texture, MaxErrorBoundHoldsOrEveryMissIsReported) {
    const Field3D f = sdf_field(40, 36, 2, 0); // not a multiple of 4 in y
    for (Format fmt : {Format::Bc4, Format::Bc1Scalar, Format::Bc1}) {
        CompressOptions o;
        o.format = fmt;
        o.max_error = 0.05f; // metres over a ~400 m range: BC4 cannot everywhere
        o.allow_over_bound = true;
        EncodedTexture e = encode_texture(f, o);
        // Every texel of a block not in the list meets the bound under every decoder:
        // check through the report's per-decoder figure when nothing was missed.
        if (e.report.blocks_over_bound.empty()) { EXPECT_LE(e.report.bound_max_error, 0.05 + 1e-4); }
        else {
            float worst = 0;
            for (const BlockMiss& b : e.report.blocks_over_bound) { EXPECT_GT(b.best_error, 0.05f); worst = std::max(worst, b.best_error); }
            EXPECT_GE(worst + 1e-3, e.report.bound_max_error * 0.999) << format_name(fmt); // the worst miss is the worst texel (mip 0)
        }
        CompressOptions loose = o;
        loose.max_error = 400.0f;
        EXPECT_TRUE(encode_texture(f, loose).report.blocks_over_bound.empty());
    }
}

TEST(Texture, BoundFailureThrowsAndWritesNothing) {
    const fs::path dir = temp_dir();
    CompressOptions o;
    o.format = Format::Bc4;
    o.max_error = 1e-6f;
    try {
        compress_to_dds(sdf_field(16, 16, 1, 0), dir / "fail.dds", o);
        FAIL() << "expected BoundError";
    } catch (const BoundError& e) {
        EXPECT_FALSE(e.report().blocks_over_bound.empty());
        EXPECT_NE(std::string(e.what()).find("block at"), std::string::npos);
        // It says what bound is reachable, and that bound does pass.
        const std::string what = e.what();
        const std::string key = "this encoding reaches max_error ";
        const size_t at = what.find(key);
        ASSERT_NE(at, std::string::npos) << what;
        const float reach = std::stof(what.substr(at + key.size()));
        EXPECT_GT(reach, 1e-6f);
        CompressOptions ok = o;
        ok.max_error = reach;
        EXPECT_NO_THROW(compress_to_dds(sdf_field(16, 16, 1, 0), dir / "reach.dds", ok)) << what;
        // And what each quality level reaches (a small texture: encoded again at each), each of
        // which passes at its level.
        for (Quality q : {Quality::Fast, Quality::Normal, Quality::Best}) {
            const std::string qk = std::string(q == Quality::Fast ? "at quality " : ", ") + quality_name(q) + " ";
            const size_t qa = what.find(qk);
            ASSERT_NE(qa, std::string::npos) << qk << " in " << what;
            CompressOptions at_q = o;
            at_q.quality = q;
            at_q.max_error = std::stof(what.substr(qa + qk.size()));
            EXPECT_NO_THROW(compress_to_dds(sdf_field(16, 16, 1, 0), dir / "reach_q.dds", at_q)) << quality_name(q) << ": " << what;
        }
    }
    EXPECT_FALSE(fs::exists(dir / "fail.dds"));
    EXPECT_FALSE(fs::exists(dir / "fail.dds.json"));
}

TEST(Texture, WrittenOverTheBoundTheManifestStatesTheBoundItHolds) {
    const fs::path dir = temp_dir();
    CompressOptions o;
    o.format = Format::Bc4;
    o.max_error = 1e-6f;
    o.allow_over_bound = true;
    const Field3D f = sdf_field(16, 16, 1, 0);
    const CompressReport r = compress_to_dds(f, dir / "over.dds", o);
    ASSERT_FALSE(r.blocks_over_bound.empty());
    const auto m = io::read_dds_manifest(dir / "over.dds");
    ASSERT_TRUE(m && m->max_error && m->requested_max_error);
    EXPECT_FLOAT_EQ(*m->requested_max_error, 1e-6f);
    EXPECT_GT(*m->max_error, 1e-6f);
    // The stated bound holds: the file decoded again under every decoder model is within it.
    const CompressReport v = verify_dds(dir / "over.dds", f);
    EXPECT_LE(v.bound_max_error, *m->max_error * (1 + 1e-6)) << *m->max_error;
    // Within the bound, the manifest says nothing more.
    o.max_error = *m->max_error;
    compress_to_dds(f, dir / "ok.dds", o);
    const auto ok = io::read_dds_manifest(dir / "ok.dds");
    ASSERT_TRUE(ok);
    EXPECT_FALSE(ok->requested_max_error.has_value());
}

TEST(Texture, VolumeRoundTripWithMips) {
    const fs::path dir = temp_dir();
    const Field3D f = sdf_field(64, 64, 16, 0);
    for (bool os : {false, true}) {
        CompressOptions o;
        o.format = Format::Bc4;
        o.mip_levels = 0;
        o.one_sided_below = os;
        const fs::path p = dir / (os ? "vol_os.dds" : "vol.dds");
        CompressReport r = compress_to_dds(f, p, o);
        EXPECT_EQ(r.mip_levels, 7);
        DdsTexture t = read_dds_file(p);
        EXPECT_TRUE(t.volume);
        EXPECT_EQ(t.depth, 16);
        EXPECT_EQ(t.mip_levels, 7);
        EXPECT_EQ(t.level_depth(1), 8);
        EXPECT_EQ(t.level_depth(6), 1);
        EXPECT_EQ(t.level_size(0), uint64_t(16 * 16 * 16 * 8));
        Field3D back = read_dds(p);
        ASSERT_EQ(back.resolution(), f.resolution());
        double worst = 0;
        for (size_t i = 0; i < f.voxel_count(); ++i) {
            worst = std::max(worst, double(std::fabs(back.channel(0)[i] - f.channel(0)[i])));
            if (os) { ASSERT_LE(back.channel(0)[i], f.channel(0)[i]) << i; }
        }
        EXPECT_NEAR(worst, r.max_error[0], 1e-3);
        // Verification from the file agrees with the encoder's report.
        CompressReport v = verify_dds(p, f);
        EXPECT_NEAR(v.bound_max_error, r.bound_max_error, 1e-4);
        // Sidecar manifest.
        std::ifstream m(fs::path(p.string() + ".json"));
        std::string text((std::istreambuf_iterator<char>(m)), {});
        TextureManifest man = TextureManifest::from_json(text, "manifest");
        EXPECT_EQ(man.encoding, "bc4");
        EXPECT_EQ(man.mip_filter, os ? "min" : "box");
        EXPECT_EQ(man.depth, 16);
    }
}

TEST(Texture, OneSidedMipsAreBelowEveryCoveredTexel) {
    const Field3D f = sdf_field(20, 12, 6, 2);
    CompressOptions o;
    o.format = Format::R32F; // exact storage: checks the reduction itself
    o.mip_levels = 0;
    o.one_sided_below = true;
    EncodedTexture e = encode_texture(f, o);
    const DdsTexture& t = e.dds;
    // Level 1 texel (x, y, z) covers level-0 texels 2x..2x+1 (+ the odd leftover).
    const float* l1 = reinterpret_cast<const float*>(t.data.data() + t.offset(0, 1));
    const int w1 = t.level_width(1), h1 = t.level_height(1), d1 = t.level_depth(1);
    for (int z = 0; z < f.nz(); ++z)
        for (int y = 0; y < f.ny(); ++y)
            for (int x = 0; x < f.nx(); ++x) {
                // DDS rows run top-down: field row y is stored as row ny - 1 - y.
                const int row = f.ny() - 1 - y;
                const int X = std::min(x / 2, w1 - 1), Y = std::min(row / 2, h1 - 1), Z = std::min(z / 2, d1 - 1);
                ASSERT_LE(l1[(size_t(Z) * h1 + Y) * w1 + X], f.at(0, x, y, z));
            }
}

TEST(Texture, UncompressedFormatsRoundTrip) {
    const fs::path dir = temp_dir();
    Field3D f(Vec3i{{9, 7, 3}}, 4, Box3d{{{0, 0, 0}}, {{1, 1, 1}}});
    for (int c = 0; c < 4; ++c)
        for (size_t i = 0; i < f.voxel_count(); ++i) f.channel(c)[i] = float(std::sin(double(i) * 0.37 + c) * 0.5 + 0.5);
    struct Case { Format f; double tol; };
    for (Case k : {Case{Format::R8, 0.5 / 255}, Case{Format::R16, 0.5 / 65535}, Case{Format::R16F, 1e-3}, Case{Format::R32F, 0},
                   Case{Format::Rgba8, 0.5 / 255}, Case{Format::Rgba16F, 1e-3}, Case{Format::Rgba4, 0.5 / 15}}) {
        CompressOptions o;
        o.format = k.f;
        o.value_range = std::make_pair(0.0f, 1.0f);
        o.as_array = true;
        const fs::path p = dir / (std::string(format_name(k.f)) + ".dds");
        CompressReport r = compress_to_dds(f, p, o);
        Field3D back = read_dds(p);
        EXPECT_EQ(back.nz(), 3);
        for (int c = 0; c < back.channels(); ++c)
            for (size_t i = 0; i < f.voxel_count(); ++i)
                ASSERT_NEAR(back.channel(c)[i], f.channel(c)[i], k.tol + 1e-7) << format_name(k.f) << " c" << c;
        EXPECT_LE(r.bound_max_error, k.tol + 1e-7) << format_name(k.f);
    }
}

// The file is written as header and data in two pieces: its bytes are what
// encode_dds joins in memory, with the DX10 and the legacy FourCC headers.
TEST(Texture, FileBytesAreTheEncodedTexture) {
    const fs::path dir = temp_dir();
    const Field3D f = sdf_field(20, 12, 3, 0);
    for (int k = 0; k < 3; ++k) {
        CompressOptions o;
        o.format = k == 2 ? Format::Bc4 : Format::Bc1;
        o.legacy_bc1_header = k == 1;
        o.mip_levels = 0;
        const fs::path p = dir / ("bytes" + std::to_string(k) + ".dds");
        compress_to_dds(f, p, o);
        std::ifstream in(p, std::ios::binary);
        const std::vector<uint8_t> file((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        const DdsTexture tex = encode_texture(f, o).dds;
        EXPECT_EQ(file, encode_dds(tex)) << "case " << k;
        EXPECT_EQ(file.size(), encode_dds_header(tex).size() + tex.data.size()) << "case " << k;
    }
}

TEST(Texture, SameBytesForAnyThreadCount) {
    const Field3D f = sdf_field(48, 40, 3, 0);
    for (Format fmt : {Format::Bc4, Format::Bc1Scalar, Format::Bc1}) {
        CompressOptions o;
        o.format = fmt;
        o.one_sided_below = fmt != Format::Bc1;
        o.mip_levels = 0;
        std::vector<uint8_t> one, many;
        {
            tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
            one = encode_dds(encode_texture(f, o).dds);
        }
        many = encode_dds(encode_texture(f, o).dds);
        EXPECT_EQ(one, many) << format_name(fmt);
    }
}

TEST(Texture, NanAndInfAreErrorsNamingTheTexel) {
    Field3D f = sdf_field(8, 8, 1, 1);
    f.at(0, 3, 5, 0) = NAN;
    CompressOptions o;
    try {
        encode_texture(f, o);
        FAIL();
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("texel (3, 5, 0)"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("NaN"), std::string::npos);
    }
    f.at(0, 3, 5, 0) = INFINITY;
    EXPECT_THROW(encode_texture(f, o), Error);
    f.at(0, 3, 5, 0) = 1e6f; // outside an explicit range
    o.value_range = std::make_pair(0.0f, 10.0f);
    EXPECT_THROW(encode_texture(f, o), Error);
    o.format = Format::Bc6hUf16;
    o.one_sided_below = true; // BC6H refuses one-sided bounds
    EXPECT_THROW(encode_texture(sdf_field(8, 8, 1, 1), o), Error);
    EXPECT_THROW(parse_format("bc7"), Error);
}

TEST(Texture, CorruptDdsIsAnError) {
    std::vector<uint8_t> junk(200, 7);
    EXPECT_THROW(decode_dds(junk), Error);
    CompressOptions o;
    EncodedTexture e = encode_texture(sdf_field(8, 8, 1, 0), o);
    std::vector<uint8_t> b = encode_dds(e.dds);
    b.resize(b.size() - 3);
    EXPECT_THROW(decode_dds(b), Error);
}

TEST(Texture, SweepRowsImproveWithQuality) {
    CompressOptions o;
    o.format = Format::Bc4;
    auto rows = sweep(sdf_field(16, 16, 1, 0), o);
    ASSERT_EQ(rows.size(), 3u);
    EXPECT_LE(rows[2].max_error, rows[1].max_error + 1e-9);
    const std::string csv = sweep_csv(rows);
    EXPECT_EQ(csv.rfind("quality,max_error,rmse,seconds\nfast,", 0), 0u) << csv;
    EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 4);
}

TEST(Texture, ReportJsonHasTheDocumentedKeys) {
    CompressOptions o;
    o.format = Format::Bc4;
    o.max_error = 1e-6f;
    o.allow_over_bound = true;
    const std::string j = encode_texture(sdf_field(8, 8, 1, 0), o).report.to_json();
    for (const char* key : {"\"max_error\"", "\"rmse\"", "\"psnr\"", "\"blocks_over_bound\"", "\"encode_seconds\"", "\"verify_seconds\"",
                            "\"texels_per_second\"", "\"one_sided_violations\"", "\"decoder\": \"conformant\""})
        EXPECT_NE(j.find(key), std::string::npos) << key;
}

} // namespace
} // namespace atlas::compress

namespace atlas::compress {
namespace {

// Malformed headers: every single-byte mutation of the header of a valid file either
// parses to a consistent texture or throws atlas::Error (never crashes or overreads).
TEST(Texture, MutatedDdsHeadersNeverCrash) {
    CompressOptions o;
    o.format = Format::Bc4;
    o.mip_levels = 0;
    const std::vector<uint8_t> good = encode_dds(encode_texture(sdf_field(12, 8, 3, 0), o).dds);
    int parsed = 0, rejected = 0;
    for (size_t at = 0; at < 148; ++at)
        for (int v : {0, 1, 3, 0x7f, 0xff}) {
            std::vector<uint8_t> b = good;
            b[at] = uint8_t(v);
            try {
                DdsTexture t = decode_dds(b);
                ASSERT_EQ(t.data.size(), t.total_bytes());
                if (t.format == DxgiFormat::BC6H_UF16 || t.format == DxgiFormat::BC6H_SF16) { ++parsed; continue; }
                decode_texture(t, nullptr);
                ++parsed;
            } catch (const Error&) {
                ++rejected;
            }
        }
    EXPECT_GT(parsed, 0);
    EXPECT_GT(rejected, 0);
}

} // namespace
// The cloud type convention (issue 44): Atlas's 0, 1/3, 2/3, 1 or GPU Pro 7's 0, 0.5, 1, named
// in the manifest; the texture stores the converted values.
TEST(Texture, TypeEncodingConvertsTheTypeChannelsAndNamesItsConvention) {
    const fs::path dir = temp_dir();
    Field3D f({{8, 8, 1}}, 2, Box3d{{{0, 0, 0}}, {{8, 8, 1}}}, {"coverage", "type"});
    for (int i = 0; i < 64; ++i) {
        f.channel(0)[size_t(i)] = float(i) / 63.0f;
        f.channel(1)[size_t(i)] = float(i % 4) / 3.0f; // stratus, stratocumulus, cumulus, cumulonimbus
    }
    CompressOptions o;
    o.format = Format::Rgba16F;
    compress_to_dds(f, dir / "atlas.dds", o);
    o.type_encoding = TypeEncoding::GpuPro7;
    compress_to_dds(f, dir / "gp7.dds", o);
    const auto ma = io::read_dds_manifest(dir / "atlas.dds");
    const auto mg = io::read_dds_manifest(dir / "gp7.dds");
    ASSERT_TRUE(ma && mg);
    EXPECT_EQ(ma->type_encoding, "atlas");
    EXPECT_EQ(mg->type_encoding, "gpu_pro_7");
    ASSERT_GE(mg->channel_meanings.size(), 2u);
    EXPECT_EQ(mg->channel_meanings[0], "coverage");
    EXPECT_NE(mg->channel_meanings[1].find("0.5 stratocumulus"), std::string::npos) << mg->channel_meanings[1];
    const Field3D a = read_dds(dir / "atlas.dds");
    const Field3D g = read_dds(dir / "gp7.dds");
    const float expect[4] = {0.0f, 0.5f, 1.0f, 1.0f}; // cumulonimbus becomes cumulus
    for (int i = 0; i < 64; ++i) {
        EXPECT_NEAR(a.channel(1)[size_t(i)], float(i % 4) / 3.0f, 1e-3f) << i;
        EXPECT_NEAR(g.channel(1)[size_t(i)], expect[i % 4], 1e-3f) << i;
        EXPECT_EQ(g.channel(0)[size_t(i)], a.channel(0)[size_t(i)]) << i; // other channels untouched
    }
    // Data without a type channel: a clear error, nothing written; the option's names are listed.
    Field3D plain({{8, 8, 1}}, 1, Box3d{{{0, 0, 0}}, {{8, 8, 1}}}, {"density"});
    o.format = Format::R16F;
    try {
        compress_to_dds(plain, dir / "plain.dds", o);
        FAIL() << "expected an error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("none is stored (stored: density)"), std::string::npos) << e.what();
    }
    EXPECT_FALSE(fs::exists(dir / "plain.dds"));
    EXPECT_THROW(parse_type_encoding("hzd"), Error);
    // A field without type channels says nothing about a convention.
    o.type_encoding = TypeEncoding::Atlas;
    compress_to_dds(plain, dir / "plain.dds", o);
    EXPECT_TRUE(io::read_dds_manifest(dir / "plain.dds")->type_encoding.empty());
}

} // namespace atlas::compress

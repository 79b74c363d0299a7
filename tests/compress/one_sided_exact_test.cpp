// The one-sided (decoded <= source) and max-error promises hold for a decoder that
// computes in double: the DDS bytes are decoded here, following the D3D functional
// specification's formulas in double precision (not Atlas's decoder), and mapped back
// as an engine does, lo + n * (hi - lo) in double, against the float sources.
//
// Half of the texels are snapped to the format's own decode levels (the float nearest
// lo + level * (hi - lo), and its neighbouring floats): there a float comparison
// says "equal" while the exact value may be an ulp above, which is where a float-only
// check lets a texel slip.
#include "atlas/compress/bc1_scalar.h"
#include "atlas/compress/texture.h"
#include "test_blocks.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <set>
#include <tuple>
#include <vector>

namespace atlas::compress {
namespace {

using test::unit;

constexpr float kLo = -256.0f, kHi = 4096.0f;

#if defined(ATLAS_SANITIZED) || !defined(NDEBUG)
constexpr int kNx = 32, kNy = 32, kNz = 4;
#else
constexpr int kNx = 96, kNy = 64, kNz = 8;
#endif

uint32_t rd32(const uint8_t* p) { return uint32_t(p[0]) | (uint32_t(p[1]) << 8) | (uint32_t(p[2]) << 16) | (uint32_t(p[3]) << 24); }

// Level 0 of a DDS file (2D or volume, one array element) decoded in double per the
// D3D11 functional specification: UNORM c / (2^n - 1), SNORM max(c, -127) / 127, BC1
// colour interpolation (2c0 + c1) / 3 etc. on the expanded endpoints, BC4 red
// interpolation. Returns n per texel (x fastest, DDS row order) for channel `ch`;
// for BC1 the three colour channels are combined with `weights` (bc1-scalar's unpack).
struct Level0 {
    int w = 0, h = 0, d = 1;
    std::vector<double> n;
};

Level0 decode_level0(const std::vector<uint8_t>& file, int ch, const std::array<double, 3>& weights) {
    EXPECT_EQ(std::memcmp(file.data(), "DDS ", 4), 0);
    const uint8_t* hdr = file.data() + 4;
    Level0 L;
    L.h = int(rd32(hdr + 8));
    L.w = int(rd32(hdr + 12));
    const uint32_t flags = rd32(hdr + 4);
    L.d = (flags & 0x800000u) ? std::max(1, int(rd32(hdr + 20))) : 1; // DDSD_DEPTH
    const uint8_t* pf = hdr + 72;
    const uint32_t fourcc = rd32(pf + 8);
    size_t off = 4 + 124;
    uint32_t dxgi = 0;
    if (fourcc == rd32(reinterpret_cast<const uint8_t*>("DX10"))) {
        dxgi = rd32(file.data() + off);
        off += 20;
    } else if (fourcc == rd32(reinterpret_cast<const uint8_t*>("DXT1"))) {
        dxgi = 71;
    } else if (fourcc == rd32(reinterpret_cast<const uint8_t*>("ATI1")) || fourcc == rd32(reinterpret_cast<const uint8_t*>("BC4U"))) {
        dxgi = 80;
    } else {
        ADD_FAILURE() << "unexpected DDS pixel format";
        return L;
    }
    const uint8_t* data = file.data() + off;
    L.n.assign(size_t(L.w) * size_t(L.h) * size_t(L.d), 0.0);
    auto at = [&](int x, int y, int z) -> double& { return L.n[(size_t(z) * size_t(L.h) + size_t(y)) * size_t(L.w) + size_t(x)]; };
    const int bw = std::max(1, (L.w + 3) / 4), bh = std::max(1, (L.h + 3) / 4);
    for (int z = 0; z < L.d; ++z)
        for (int y = 0; y < L.h; ++y)
            for (int x = 0; x < L.w; ++x) {
                const size_t i = (size_t(z) * size_t(L.h) + size_t(y)) * size_t(L.w) + size_t(x);
                switch (dxgi) {
                case 61: at(x, y, z) = data[i] / 255.0; break;                                    // R8_UNORM
                case 56: at(x, y, z) = (data[2 * i] | (data[2 * i + 1] << 8)) / 65535.0; break;  // R16_UNORM
                case 28: at(x, y, z) = data[4 * i + size_t(ch)] / 255.0; break;                   // R8G8B8A8_UNORM
                case 115: { // B4G4R4A4_UNORM: B bits 0-3, G 4-7, R 8-11, A 12-15
                    const int v = data[2 * i] | (data[2 * i + 1] << 8);
                    const int shift[4] = {8, 4, 0, 12};
                    at(x, y, z) = ((v >> shift[ch]) & 15) / 15.0;
                    break;
                }
                default: break;
                }
            }
    if (dxgi == 71 || dxgi == 80 || dxgi == 81) {
        for (int z = 0; z < L.d; ++z)
            for (int by = 0; by < bh; ++by)
                for (int bx = 0; bx < bw; ++bx) {
                    const uint8_t* b = data + ((size_t(z) * size_t(bh) + size_t(by)) * size_t(bw) + size_t(bx)) * 8;
                    double pal[8] = {};
                    int idx[16];
                    if (dxgi == 71) {
                        const int c0 = b[0] | (b[1] << 8), c1 = b[2] | (b[3] << 8);
                        auto rgb = [](int c, double out[3]) { out[0] = (c >> 11) / 31.0; out[1] = ((c >> 5) & 63) / 63.0; out[2] = (c & 31) / 31.0; };
                        double e0[3], e1[3], p[4][3];
                        rgb(c0, e0);
                        rgb(c1, e1);
                        for (int k = 0; k < 3; ++k) {
                            p[0][k] = e0[k];
                            p[1][k] = e1[k];
                            if (c0 > c1) {
                                p[2][k] = (2.0 * e0[k] + e1[k]) / 3.0;
                                p[3][k] = (e0[k] + 2.0 * e1[k]) / 3.0;
                            } else {
                                p[2][k] = (e0[k] + e1[k]) / 2.0;
                                p[3][k] = 0.0; // black
                            }
                        }
                        for (int i = 0; i < 4; ++i) pal[i] = p[i][0] * weights[0] + p[i][1] * weights[1] + p[i][2] * weights[2];
                        const uint32_t bits = rd32(b + 4);
                        for (int t = 0; t < 16; ++t) idx[t] = int((bits >> (2 * t)) & 3);
                    } else {
                        double r0, r1;
                        if (dxgi == 80) { r0 = b[0] / 255.0; r1 = b[1] / 255.0; }
                        else { r0 = std::max(int(int8_t(b[0])), -127) / 127.0; r1 = std::max(int(int8_t(b[1])), -127) / 127.0; }
                        pal[0] = r0;
                        pal[1] = r1;
                        if (r0 > r1)
                            for (int i = 2; i < 8; ++i) pal[i] = ((8 - i) * r0 + (i - 1) * r1) / 7.0;
                        else {
                            for (int i = 2; i < 6; ++i) pal[i] = ((6 - i) * r0 + (i - 1) * r1) / 5.0;
                            pal[6] = dxgi == 81 ? -1.0 : 0.0;
                            pal[7] = 1.0;
                        }
                        uint64_t bits = 0;
                        for (int i = 0; i < 6; ++i) bits |= uint64_t(b[2 + i]) << (8 * i);
                        for (int t = 0; t < 16; ++t) idx[t] = int((bits >> (3 * t)) & 7);
                    }
                    for (int t = 0; t < 16; ++t) {
                        const int x = bx * 4 + t % 4, y = by * 4 + t / 4;
                        if (x < L.w && y < L.h) at(x, y, z) = pal[idx[t]];
                    }
                }
    }
    return L;
}

// Normalized decode levels of a format (a sample of them), to snap sources onto.
double decode_level(Format f, uint64_t k, const std::array<double, 3>& w) {
    const double a = unit(k, 7);
    switch (f) {
    case Format::R8: case Format::Rgba8: return std::floor(a * 256) / 255.0;
    case Format::R16: return std::floor(a * 65536) / 65535.0;
    case Format::Rgba4: return std::floor(a * 16) / 15.0;
    case Format::Bc4: { // endpoints and interpolants of random pairs
        const int e0 = int(unit(k, 8) * 256), e1 = int(unit(k, 9) * 256), i = int(unit(k, 10) * 8);
        return ((7 - i) * e0 + i * e1) / (7.0 * 255.0);
    }
    case Format::Bc4Snorm: {
        const int e0 = int(unit(k, 8) * 255) - 127, e1 = int(unit(k, 9) * 255) - 127, i = int(unit(k, 10) * 8);
        return ((7 - i) * e0 + i * e1) / (7.0 * 127.0);
    }
    case Format::Bc1Scalar: { // an endpoint value or a third of the way between two
        const int c0 = int(unit(k, 8) * 65536), c1 = std::min(65535, c0 + int(unit(k, 9) * 64));
        auto v = [&](int c) { return (c >> 11) / 31.0 * w[0] + ((c >> 5) & 63) / 63.0 * w[1] + (c & 31) / 31.0 * w[2]; };
        const int i = int(unit(k, 10) * 3);
        return ((3 - i) * v(c0) + i * v(c1)) / 3.0;
    }
    default: return a;
    }
}

Field3D make_field(Format f, const std::array<double, 3>& w) {
    Field3D field(Vec3i{{kNx, kNy, kNz}}, 1, Box3d{{{0, 0, 0}}, {{kNx * 8.0, kNy * 8.0, kNz * 8.0}}}, {"sdf"});
    const bool snorm = f == Format::Bc4Snorm;
    for (int z = 0; z < kNz; ++z)
        for (int y = 0; y < kNy; ++y)
            for (int x = 0; x < kNx; ++x) {
                const uint64_t k = (uint64_t(z) * kNy + uint64_t(y)) * kNx + uint64_t(x);
                // A distance field (two spheres, 8 m voxels) with some noise.
                double d = std::min(std::hypot(x * 8.0 - 300, y * 8.0 - 200, z * 8.0 - 20) - 90, std::hypot(x * 8.0 - 600, y * 8.0 - 350, z * 8.0) - 60);
                d += 3 * unit(k, 1);
                if ((x / 4 + y / 4 + z) % 2 == 0) { // snapped blocks
                    double n = decode_level(f, k, w);
                    if (snorm) n = (n + 1.0) / 2.0; // the SNORM mapping's u
                    d = double(kLo) + n * (double(kHi) - double(kLo));
                }
                float v = float(std::clamp(d, double(kLo), double(kHi)));
                const int nudge = int(unit(k, 2) * 3) - 1; // -1, 0, +1 ulp
                if (nudge < 0 && v > kLo) v = std::nextafter(v, -INFINITY);
                if (nudge > 0 && v < kHi) v = std::nextafter(v, INFINITY);
                field.at(0, x, y, z) = v;
            }
    return field;
}

struct Case {
    Format format;
    DecoderSet decoders;
    float max_error; // m; < 0: none
};

void check_exact(const Case& c) {
    const std::array<float, 3> wf = bc1_scalar_unpack(c.decoders).weights;
    const std::array<double, 3> w{double(wf[0]), double(wf[1]), double(wf[2])};
    const Field3D field = make_field(c.format, w);
    CompressOptions o;
    o.format = c.format;
    o.one_sided_below = true;
    o.decoders = c.decoders;
    o.value_range = {{kLo, kHi}};
    if (c.max_error >= 0) o.max_error = c.max_error;
    const EncodedTexture e = encode_texture(field, o);
    const std::vector<uint8_t> file = encode_dds(e.dds);
    const std::array<double, 3> mw{double(e.manifest.unpack_weights[0]), double(e.manifest.unpack_weights[1]), double(e.manifest.unpack_weights[2])};
    const Level0 L = decode_level0(file, 0, c.format == Format::Bc1Scalar ? mw : std::array<double, 3>{1, 0, 0});
    ASSERT_EQ(L.w, kNx);
    ASSERT_EQ(L.h, kNy);
    ASSERT_EQ(L.d, kNz);
    const double lo = e.manifest.range_lo, hi = e.manifest.range_hi;
    const bool snorm = c.format == Format::Bc4Snorm;
    auto value = [&](double n) { return lo + (snorm ? (n + 1.0) / 2.0 : n) * (hi - lo); };
    // DDS row order: the orientation under which this decode matches Atlas's own
    // (float) decode of the texture, which returns the field's orientation.
    const Field3D atlas = decode_texture(e.dds, &e.manifest, Decoder::Reference);
    double diff[2] = {0, 0};
    for (int flip = 0; flip < 2; ++flip)
        for (int z = 0; z < kNz; ++z)
            for (int y = 0; y < kNy; ++y)
                for (int x = 0; x < kNx; ++x) {
                    const int row = flip ? kNy - 1 - y : y;
                    diff[flip] = std::max(diff[flip], std::fabs(value(L.n[(size_t(z) * kNy + size_t(row)) * kNx + size_t(x)]) - atlas.at(0, x, y, z)));
                }
    const int flip = diff[1] < diff[0] ? 1 : 0;
    ASSERT_LT(diff[flip], 0.01) << "the double decode does not match Atlas's decode in either row order";
    std::set<std::tuple<int, int, int>> missed;
    for (const BlockMiss& m : e.report.blocks_over_bound)
        if (m.mip == 0) missed.insert({m.x, m.y, m.z});
    int above = 0, over_bound = 0;
    double worst_above = 0, worst_err = 0;
    for (int z = 0; z < kNz; ++z)
        for (int y = 0; y < kNy; ++y)
            for (int x = 0; x < kNx; ++x) {
                const int row = flip ? kNy - 1 - y : y;
                const double dec = value(L.n[(size_t(z) * kNy + size_t(row)) * kNx + size_t(x)]);
                const double src = field.at(0, x, y, z);
                if (dec > src) {
                    ++above;
                    worst_above = std::max(worst_above, dec - src);
                }
                if (c.max_error >= 0 && !missed.count({x / 4 * 4, row / 4 * 4, z})) { // misses are in DDS texels
                    worst_err = std::max(worst_err, std::fabs(dec - src));
                    if (std::fabs(dec - src) > double(c.max_error)) ++over_bound;
                }
            }
    // BC4: a constant pair two levels below a block's minimum is always one-sided, so no
    // block's error exceeds its spread plus two levels (a guard against candidates that
    // the exact bounds make infeasible, leaving texels with the constant 0).
    if (c.format == Format::Bc4 || c.format == Format::Bc4Snorm) {
        const double level = (hi - lo) / (snorm ? 254.0 : 255.0);
        for (int z = 0; z < kNz; ++z)
            for (int by = 0; by < kNy / 4; ++by)
                for (int bx = 0; bx < kNx / 4; ++bx) {
                    double smin = INFINITY, smax = -INFINITY, worst = 0;
                    for (int t = 0; t < 16; ++t) {
                        const int x = bx * 4 + t % 4, y = by * 4 + t / 4, row = flip ? kNy - 1 - y : y;
                        const double src = field.at(0, x, y, z), dec = value(L.n[(size_t(z) * kNy + size_t(row)) * kNx + size_t(x)]);
                        smin = std::min(smin, src);
                        smax = std::max(smax, src);
                        worst = std::max(worst, std::fabs(src - dec));
                    }
                    ASSERT_LE(worst, smax - smin + 2 * level) << format_name(c.format) << " block " << bx << ", " << by << ", " << z;
                }
    }
    EXPECT_EQ(above, 0) << format_name(c.format) << ": " << above << " texels decode above the source in double, by up to " << worst_above
                        << " m";
    EXPECT_EQ(over_bound, 0) << format_name(c.format) << ": " << over_bound << " texels outside max_error " << c.max_error
                             << " m in blocks not reported as missing it (worst " << worst_err << " m)";
    // The bound must be met by most blocks, or the test checks nothing.
    if (c.max_error >= 0) { // the bound must be met by a good share of the blocks, or this checks little
        const size_t blocks = size_t(kNx / 4) * size_t(kNy / 4) * size_t(kNz);
        EXPECT_LT(missed.size(), blocks * 3 / 4) << format_name(c.format);
        std::printf("%-10s max_error %.6g m: %zu of %zu blocks reported over the bound, worst exact error elsewhere %.6f m\n",
                    format_name(c.format), double(c.max_error), missed.size(), blocks, worst_err);
    }
}

constexpr DecoderSet kRna = kReferenceOnly | decoder_bit(Decoder::Nvidia) | decoder_bit(Decoder::Amd);

TEST(ExactArithmetic, OneSidedHoldsInDoubleForBc4) { check_exact({Format::Bc4, kReferenceOnly, -1}); }
TEST(ExactArithmetic, OneSidedHoldsInDoubleForBc4Snorm) { check_exact({Format::Bc4Snorm, kReferenceOnly, -1}); }
TEST(ExactArithmetic, OneSidedHoldsInDoubleForBc1Scalar) {
    check_exact({Format::Bc1Scalar, kReferenceOnly, -1});
    check_exact({Format::Bc1Scalar, kRna, -1});
}
TEST(ExactArithmetic, OneSidedHoldsInDoubleForUncompressed) {
    for (Format f : {Format::R8, Format::R16, Format::Rgba8, Format::Rgba4}) check_exact({f, kReferenceOnly, -1});
}
// Bounds at exactly one quantisation step (uncompressed) or at what the encoders reach
// on most blocks: texels whose float error is just under the bound are where a float
// check accepts an exact error just over it.
TEST(ExactArithmetic, MaxErrorHoldsInDouble) {
    const float range = kHi - kLo;
    check_exact({Format::R8, kReferenceOnly, range / 255.0f});
    check_exact({Format::R16, kReferenceOnly, range / 65535.0f});
    check_exact({Format::Rgba4, kReferenceOnly, range / 15.0f});
    check_exact({Format::Bc4, kReferenceOnly, 6.0f});
    check_exact({Format::Bc1Scalar, kReferenceOnly, 8.0f});
}

} // namespace
} // namespace atlas::compress

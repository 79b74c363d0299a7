#include "atlas/core/error.h"
#include "atlas/core/field.h"
#include "atlas/core/field_math.h"
#include "atlas/core/hash.h"
#include "atlas/core/memory.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <memory>
#include <utility>

using namespace atlas;

namespace {
Field3D ramp3d(Vec3i res) {
    Field3D f(res, 2, Box3d{{{0, 0, 0}}, {{double(res[0]), double(res[1]), double(res[2])}}});
    for (int z = 0; z < res[2]; ++z)
        for (int y = 0; y < res[1]; ++y)
            for (int x = 0; x < res[0]; ++x) {
                f.at(0, x, y, z) = float(x + 10 * y + 100 * z);
                f.at(1, x, y, z) = float(-x);
            }
    return f;
}
} // namespace

TEST(Field3D, LayoutAndGeometry) {
    Field3D f({{4, 3, 2}}, 1, Box3d{{{-10, 0, 100}}, {{-6, 6, 104}}});
    EXPECT_EQ(f.voxel_count(), 24u);
    EXPECT_EQ(f.index(1, 0, 0), 1u);
    EXPECT_EQ(f.index(0, 1, 0), 4u);
    EXPECT_EQ(f.index(0, 0, 1), 12u);
    EXPECT_EQ(f.voxel_size(), (Vec3d{{1, 2, 2}}));
    EXPECT_EQ(f.voxel_center(0, 0, 0), (Vec3d{{-9.5, 1, 101}}));
    EXPECT_EQ(f.channel_names(), (std::vector<std::string>{"r"}));
    EXPECT_EQ(f.byte_size(), 24u * 4u);
}

TEST(Field3D, SharedChannelsAreTheSourcesUntilWritten) {
    auto a = std::make_shared<const Field3D>(ramp3d({{5, 4, 3}}));
    Field3D b0({{5, 4, 3}}, 1, a->bounds(), {"b"});
    b0.at(0, 2, 1, 1) = 7;
    auto b = std::make_shared<const Field3D>(std::move(b0));
    Field3D s = Field3D::sharing({{a, 1}, {b, 0}, {a, 0}}, {"x", "y", "z"});
    // No copy: the very samples of the sources, counted as the sources' bytes.
    EXPECT_EQ(std::as_const(s).channel(0).data(), a->channel(1).data());
    EXPECT_EQ(std::as_const(s).channel(1).data(), b->channel(0).data());
    EXPECT_EQ(s.owned_byte_size(), 0u);
    EXPECT_EQ(s.byte_size(), 3u * 60u * 4u);
    // Equal and hashed the same as a field holding copies of those channels.
    Field3D copy({{5, 4, 3}}, 3, a->bounds(), {"x", "y", "z"});
    std::copy(a->channel(1).begin(), a->channel(1).end(), copy.channel(0).begin());
    std::copy(b->channel(0).begin(), b->channel(0).end(), copy.channel(1).begin());
    std::copy(a->channel(0).begin(), a->channel(0).end(), copy.channel(2).begin());
    EXPECT_TRUE(s == copy);
    Hasher hs, hc;
    s.hash_into(hs);
    copy.hash_into(hc);
    EXPECT_EQ(hs.finish(), hc.finish());
    // A copy of a sharing field owns its channels.
    Field3D c = s;
    EXPECT_EQ(c.owned_byte_size(), c.byte_size());
    EXPECT_NE(std::as_const(c).channel(0).data(), a->channel(1).data());
    // Writing copies first: the sources never change.
    const float before = a->at(1, 3, 2, 1);
    s.at(0, 3, 2, 1) = 1000;
    EXPECT_EQ(a->at(1, 3, 2, 1), before);
    EXPECT_EQ(s.at(0, 3, 2, 1), 1000);
    EXPECT_EQ(s.at(1, 2, 1, 1), 7);
    EXPECT_EQ(s.owned_byte_size(), s.byte_size());
    // Grids must agree, channels exist.
    auto other = std::make_shared<const Field3D>(Field3D({{5, 4, 2}}, 1, Box3d{{{0, 0, 0}}, {{5, 4, 2}}}));
    EXPECT_THROW(Field3D::sharing({{a, 0}, {other, 0}}, {"p", "q"}), Error);
    EXPECT_THROW(Field3D::sharing({{a, 2}}, {"p"}), Error);
    EXPECT_THROW(Field3D::sharing({{a, 0}}, {"p", "q"}), Error);
}

TEST(Field3D, TrilinearSamplingIsExactOnLinearData) {
    Field3D f = ramp3d({{5, 4, 3}});
    // Voxel centres are at i + 0.5 in voxel coordinates.
    EXPECT_FLOAT_EQ(f.sample_voxel(0, 2.5, 1.5, 0.5, WrapMode::Clamp), 2 + 10 + 0);
    EXPECT_NEAR(f.sample_voxel(0, 1.75, 2.25, 1.5, WrapMode::Clamp), 1.25 + 17.5 + 100, 1e-4);
    EXPECT_NEAR(f.sample_world(0, {{3.0, 2.0, 1.0}}, WrapMode::Clamp), 2.5 + 15 + 50, 1e-4);
    EXPECT_FLOAT_EQ(f.sample_voxel(1, 3.0, 0.5, 0.5, WrapMode::Clamp), -2.5f);
}

TEST(Field3D, ClampAndWrap) {
    Field3D f = ramp3d({{4, 1, 1}});
    EXPECT_FLOAT_EQ(f.sample_voxel(0, -5.0, 0.5, 0.5, WrapMode::Clamp), 0.0f);
    EXPECT_FLOAT_EQ(f.sample_voxel(0, 100.0, 0.5, 0.5, WrapMode::Clamp), 3.0f);
    // Wrap: halfway between the last and the first voxel.
    EXPECT_FLOAT_EQ(f.sample_voxel(0, 4.0, 0.5, 0.5, WrapMode::Wrap), 1.5f);
    EXPECT_FLOAT_EQ(f.sample_voxel(0, 0.5 + 4 * 7, 0.5, 0.5, WrapMode::Wrap), 0.0f);
    EXPECT_FLOAT_EQ(f.sample_voxel(0, 0.5 - 4 * 3, 0.5, 0.5, WrapMode::Wrap), 0.0f);
}

TEST(Field3D, SamplingSurvivesExtremeCoordinates) {
    Field3D f = ramp3d({{4, 4, 4}});
    for (double u : {1e300, -1e300, double(NAN), double(INFINITY), -double(INFINITY), 1e12}) {
        EXPECT_TRUE(std::isfinite(f.sample_voxel(0, u, u, u, WrapMode::Clamp))) << u;
        EXPECT_TRUE(std::isfinite(f.sample_voxel(0, u, 1, 1, WrapMode::Wrap))) << u;
    }
}

TEST(Field2D, BilinearAndWrap) {
    Field2D f({{2, 2}}, 1, Box2d{{{0, 0}}, {{2, 2}}});
    f.at(0, 0, 0) = 0; f.at(0, 1, 0) = 1; f.at(0, 0, 1) = 2; f.at(0, 1, 1) = 3;
    EXPECT_FLOAT_EQ(f.sample_world(0, {{1.0, 1.0}}, WrapMode::Clamp), 1.5f);
    EXPECT_FLOAT_EQ(f.sample_texel(0, 2.0, 0.5, WrapMode::Wrap), 0.5f);
    EXPECT_FLOAT_EQ(f.sample_texel(0, 2.0, 0.5, WrapMode::Clamp), 1.0f);
}

TEST(Field, BadShapesAreClearErrors) {
    EXPECT_THROW(Field3D({{0, 4, 4}}, 1, Box3d{{{0, 0, 0}}, {{1, 1, 1}}}), Error);
    EXPECT_THROW(Field3D({{4, 4, 4}}, 0, Box3d{{{0, 0, 0}}, {{1, 1, 1}}}), Error);
    EXPECT_THROW(Field3D({{4, 4, 4}}, 1, Box3d{{{0, 0, 0}}, {{1, 0, 1}}}), Error);
    EXPECT_THROW(Field3D({{4, 4, 4}}, 1, Box3d{{{0, 0, 0}}, {{1, INFINITY, 1}}}), Error);
    EXPECT_THROW(Field2D({{4, 4}}, 2, Box2d{{{0, 0}}, {{1, 1}}}, {"only-one-name"}), Error);
}

TEST(MemoryBudget, RefusesPastTheLimitWithTheSize) {
    MemoryBudget b(1 << 20);
    EXPECT_NO_THROW(b.check(1 << 20, "x"));
    try {
        Field3D f({{256, 256, 256}}, 4, Box3d{{{0, 0, 0}}, {{1, 1, 1}}}, {}, &b);
        FAIL();
    } catch (const MemoryBudgetError& e) {
        std::string m = e.what();
        EXPECT_NE(m.find("a 3D field of 256x256x256 voxels x 4 channels needs 256.0 MiB, over the memory budget of 1.0 MiB"),
                  std::string::npos) << m;
    }
    EXPECT_EQ(MemoryBudget().limit(), 8ull << 30);
}

TEST(MemoryBudget, ParsesSizes) {
    EXPECT_EQ(parse_byte_size("8GiB"), 8ull << 30);
    EXPECT_EQ(parse_byte_size("512MiB"), 512ull << 20);
    EXPECT_EQ(parse_byte_size("2g"), 2ull << 30);
    EXPECT_EQ(parse_byte_size("1000"), 1000u);
    EXPECT_EQ(parse_byte_size("1.5KiB"), 1536u);
    EXPECT_THROW(parse_byte_size("lots"), Error);
    EXPECT_THROW(parse_byte_size("-1G"), Error);
    EXPECT_THROW(parse_byte_size("1e400"), Error);
    EXPECT_EQ(format_bytes(1536), "1.5 KiB");
}

TEST(Hash, DelimitsAndDistinguishes) {
    EXPECT_NE(Hasher().add("ab").add("c").finish(), Hasher().add("a").add("bc").finish());
    EXPECT_NE(Hasher().add(1.0).finish(), Hasher().add(int64_t(1)).finish());
    EXPECT_EQ(Hasher().add(0.0).finish(), Hasher().add(-0.0).finish());
    EXPECT_EQ(Hasher().add("x").add(3.5).finish(), Hasher().add("x").add(3.5).finish());
    EXPECT_EQ(Hasher().add("x").finish().hex().size(), 32u);
    // Field content, names and bounds all matter.
    Field3D a = ramp3d({{3, 3, 3}}), b = ramp3d({{3, 3, 3}});
    auto h = [](const Field3D& f) { Hasher hs; f.hash_into(hs); return hs.finish(); };
    EXPECT_EQ(h(a), h(b));
    b.at(1, 2, 2, 2) += 1e-6f;
    EXPECT_NE(h(a), h(b));
    Field3D c = ramp3d({{3, 3, 3}});
    c.set_channel_names({"density", "g"});
    EXPECT_NE(h(a), h(c));
}

TEST(Hash, Sha256MatchesTheFipsExamples) {
    // FIPS 180-4 examples (NIST CSRC "SHA256.pdf"), across the one- and two-block padding cases.
    EXPECT_EQ(sha256_hex(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
    EXPECT_EQ(sha256_hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
    EXPECT_EQ(sha256_hex("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
              "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
    EXPECT_EQ(sha256_hex(std::string(1000000, 'a')), "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
}

TEST(Hash, CoordinateHashIsWellSpread) {
    // Mean of hash_to_unit over a grid close to 0.5; neighbours decorrelated.
    double sum = 0, corr = 0;
    const int n = 64;
    for (int z = 0; z < n; ++z)
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) {
                double a = hash_to_unit(hash_coords(1, x, y, z)) - 0.5, b = hash_to_unit(hash_coords(1, x + 1, y, z)) - 0.5;
                sum += a;
                corr += a * b;
            }
    EXPECT_NEAR(sum / (n * n * n), 0.0, 0.01);
    EXPECT_NEAR(corr / (n * n * n) / (1.0 / 12), 0.0, 0.02);
    EXPECT_NE(hash_coords(1, 5, 6, 7), hash_coords(2, 5, 6, 7));
    EXPECT_NE(hash_coords(1, 5, 6, 7), hash_coords(1, 6, 5, 7));
}

TEST(FieldMath, BinaryRemapClampLerp) {
    auto a = std::make_shared<Field3D>(ramp3d({{4, 4, 4}}));
    Value va = Field3DPtr(a);
    auto add = std::get<Field3DPtr>(field_binary(va, {}, 2.0, BinaryOp::Add, nullptr));
    EXPECT_FLOAT_EQ(add->at(0, 1, 2, 3), 1 + 20 + 300 + 2);
    auto mul = std::get<Field3DPtr>(field_binary(va, va, 0, BinaryOp::Mul, nullptr));
    EXPECT_FLOAT_EQ(mul->at(1, 3, 0, 0), 9.0f);
    auto rm = std::get<Field3DPtr>(field_remap(va, 0, 100, 0, 1, true, nullptr));
    EXPECT_FLOAT_EQ(rm->at(0, 0, 0, 0), 0.0f);
    EXPECT_FLOAT_EQ(rm->at(0, 2, 1, 0), 0.12f);
    EXPECT_FLOAT_EQ(rm->at(0, 0, 0, 3), 1.0f); // 300 clamps
    auto degenerate = std::get<Field3DPtr>(field_remap(va, 5, 5, 0.25, 1, false, nullptr));
    EXPECT_FLOAT_EQ(degenerate->at(0, 3, 3, 3), 0.25f);
    auto cl = std::get<Field3DPtr>(field_clamp(va, -1, 10, nullptr));
    EXPECT_FLOAT_EQ(cl->at(0, 3, 3, 3), 10.0f);
    EXPECT_FLOAT_EQ(cl->at(1, 3, 3, 3), -1.0f);
    auto lp = std::get<Field3DPtr>(field_lerp(va, add, {}, 0.25, nullptr));
    EXPECT_FLOAT_EQ(lp->at(0, 0, 0, 0), 0.5f);
    EXPECT_EQ(a->at(0, 1, 2, 3), 321.0f) << "inputs are never modified";
    // Mismatched resolution is a clear error.
    Value small = Field3DPtr(std::make_shared<Field3D>(ramp3d({{2, 2, 2}})));
    EXPECT_THROW(field_binary(va, small, 0, BinaryOp::Add, nullptr), Error);
    EXPECT_THROW(field_clamp(va, 2, 1, nullptr), Error);
}

TEST(FieldMath, ResampleIdentityAndLinear) {
    Field3D f = ramp3d({{8, 8, 8}});
    Field3D same = resample_field(f, f.resolution(), f.bounds(), WrapMode::Clamp, nullptr);
    EXPECT_TRUE(same == f);
    Field3D half = resample_field(f, {{4, 4, 4}}, f.bounds(), WrapMode::Clamp, nullptr);
    // Linear data: the sample at a coarse centre equals the average of fine ones.
    EXPECT_NEAR(half.at(0, 1, 1, 1), 2.5 + 25 + 250, 1e-3);
}

TEST(FieldMath, SameResultForAnyThreadCount) {
    Field3D f = ramp3d({{64, 64, 32}});
    Value v = Field3DPtr(std::make_shared<Field3D>(f));
    Value r1, r2;
    tbb::task_arena(1).execute([&] { r1 = field_remap(v, 3, 7000, -1, 1, false, nullptr); });
    tbb::task_arena(2).execute([&] { r2 = field_remap(v, 3, 7000, -1, 1, false, nullptr); });
    EXPECT_TRUE(values_equal(r1, r2));
}

TEST(FieldMath, Stats) {
    std::vector<float> v{1, 2, 3, NAN, INFINITY};
    auto s = channel_stats(v);
    EXPECT_EQ(s.min, 1);
    EXPECT_EQ(s.max, 3);
    EXPECT_EQ(s.mean, 2);
    EXPECT_EQ(s.nan_count, 1u);
    EXPECT_EQ(s.inf_count, 1u);
}

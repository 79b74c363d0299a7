#include "atlas/core/error.h"
#include "atlas/volume/sdf.h"
#include "volume_test_util.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <limits>

using namespace atlas;
using namespace atlas::volume;
using atlas::volume::test::random_blobs;
using atlas::volume::test::sphere_density;

namespace {

Box3d cube_box(Vec3i res, double h) { return {{{0, 0, 0}}, {{res[0] * h, res[1] * h, res[2] * h}}}; }

void expect_all_finite(const Field3D& f) {
    for (float v : f.channel(0)) ASSERT_TRUE(std::isfinite(v));
}

} // namespace

// The EDT is exact with respect to the crossing points: it must equal the
// brute-force minimum over all crossings, for random shapes and anisotropic voxels.
TEST(SdfEdt, MatchesBruteForceOnRandomShapes) {
    const Vec3d voxels[] = {{{1, 1, 1}}, {{2, 1, 0.5}}, {{8, 8, 8}}};
    for (unsigned seed = 1; seed <= 6; ++seed) {
        for (const Vec3d& v : voxels) {
            Field3D d = random_blobs({{23, 19, 14}}, v, seed);
            SdfOptions o;
            o.iso = 0.4;
            o.border_is_outside = seed % 2 == 0;
            SdfStats st;
            Field3D e = sdf_from_density_edt(d, o, nullptr, &st);
            Field3D b = sdf_brute_force(d, o);
            const SdfError err = compare_sdf(e, b);
            EXPECT_EQ(err.sign_mismatches, 0u) << "seed " << seed;
            EXPECT_LT(err.max_abs_voxels, 1e-4) << "seed " << seed << " voxel " << v[0] << "," << v[1] << "," << v[2];
            EXPECT_GT(st.crossings, 0u);
            // Sign is exactly the inside test.
            for (size_t i = 0; i < d.voxel_count(); ++i) ASSERT_EQ(d.channel(0)[i] > 0.4f, e.channel(0)[i] < 0);
        }
    }
}

// Against the true sphere: distance to crossing points vs the analytic
// surface; the documented bound is 0.5 voxel.
TEST(SdfEdt, SphereWithinHalfVoxelOfAnalytic) {
    const Vec3i res{{48, 48, 48}};
    const double h = 8.0;
    const Vec3d c{{190.3, 201.7, 187.1}};
    const double r = 121.0;
    Field3D d = sphere_density(res, cube_box(res, h), c, r);
    Field3D e = sdf_from_density_edt(d, {});
    double worst = 0;
    for (int z = 0; z < res[2]; ++z)
        for (int y = 0; y < res[1]; ++y)
            for (int x = 0; x < res[0]; ++x) {
                const double truth = length(d.voxel_center(x, y, z) - c) - r;
                worst = std::max(worst, std::abs(e.at(0, x, y, z) - truth));
            }
    EXPECT_LT(worst / h, 0.5);
}

TEST(SdfEdt, EikonalAwayFromMedialAxis) {
    const Vec3i res{{40, 40, 40}};
    const double h = 1.0;
    const Vec3d c{{20.2, 19.6, 20.4}};
    Field3D d = sphere_density(res, cube_box(res, h), c, 11.0);
    Field3D e = sdf_from_density_edt(d, {});
    // Medial axis of a sphere: its centre. Keep 3 voxels away from it and 1.5
    // voxels from the surface (where the distance to discrete crossings kinks).
    auto mask = [&](int x, int y, int z) {
        const double rr = length(e.voxel_center(x, y, z) - c);
        return rr > 3 && std::abs(rr - 11.0) > 1.5;
    };
    const EikonalResidual res_e = eikonal_residual(e, 0, mask);
    EXPECT_GT(res_e.voxels, 1000u);
    EXPECT_LT(res_e.mean, 0.02);
    EXPECT_LT(res_e.max, 0.15);
}

TEST(SdfFastSweeping, SignExactErrorBounded) {
    for (unsigned seed = 1; seed <= 3; ++seed) {
        Field3D d = random_blobs({{24, 20, 16}}, {{4, 4, 4}}, seed);
        SdfOptions o;
        SdfStats st;
        Field3D f = sdf_from_density_fast_sweeping(d, o, 1, nullptr, &st);
        // fogToSdf sees beyond the grid as empty.
        o.border_is_outside = true;
        Field3D b = sdf_brute_force(d, o);
        const SdfError err = compare_sdf(f, b);
        EXPECT_EQ(err.sign_mismatches, 0u);
        // Fast sweeping is first order (no sub-voxel seeds): documented bound
        // 2 voxels (measured 0.6-0.75 here, 1.6 on the 512x512x64 bench grid).
        EXPECT_LT(err.max_abs_voxels, 2.0) << "seed " << seed;
        EXPECT_LT(err.rms_voxels, 0.5) << "seed " << seed;
        expect_all_finite(f);
    }
}

TEST(SdfFastSweeping, RejectsAnisotropicVoxels) {
    Field3D d = random_blobs({{8, 8, 8}}, {{1, 1, 2}}, 3);
    EXPECT_THROW(sdf_from_density_fast_sweeping(d, {}), Error);
}

TEST(SdfDegenerate, EmptyGridIsFarOutside) {
    Field3D d({{10, 12, 6}}, 1, cube_box({{10, 12, 6}}, 8));
    const double diag = std::sqrt(80.0 * 80 + 96.0 * 96 + 48.0 * 48);
    for (int m = 0; m < 2; ++m) {
        Field3D e = m == 0 ? sdf_from_density_edt(d, {}) : sdf_from_density_fast_sweeping(d, {});
        for (float v : e.channel(0)) ASSERT_NEAR(v, diag, 1e-3);
    }
    SdfOptions o;
    o.far_distance = 4096;
    const Field3D e4096 = sdf_from_density_edt(d, o);
    for (float v : e4096.channel(0)) ASSERT_EQ(v, 4096.0f);
}

TEST(SdfDegenerate, FullGrid) {
    Field3D d({{9, 7, 5}}, 1, cube_box({{9, 7, 5}}, 2));
    std::fill(d.channel(0).begin(), d.channel(0).end(), 1.0f);
    const Field3D inside = sdf_from_density_edt(d, {});
    for (float v : inside.channel(0)) ASSERT_LT(v, 0);
    const Field3D swept = sdf_from_density_fast_sweeping(d, {});
    for (float v : swept.channel(0)) ASSERT_LT(v, 0);
    // With the border as outside, the surface is the grid face: distance to
    // the nearest face from the voxel centre.
    SdfOptions o;
    o.border_is_outside = true;
    Field3D e = sdf_from_density_edt(d, o);
    for (int z = 0; z < 5; ++z)
        for (int y = 0; y < 7; ++y)
            for (int x = 0; x < 9; ++x) {
                const double face = 2.0 * std::min({x + 0.5, 9 - x - 0.5, y + 0.5, 7 - y - 0.5, z + 0.5, 5 - z - 0.5});
                ASSERT_NEAR(e.at(0, x, y, z), -face, 1e-5);
            }
}

TEST(SdfDegenerate, SingleVoxel) {
    const Vec3i res{{11, 11, 11}};
    Field3D d(res, 1, cube_box(res, 1));
    d.at(0, 5, 5, 5) = 1.0f;
    Field3D e = sdf_from_density_edt(d, {});
    // Crossings: the six edge midpoints around voxel (5,5,5).
    for (int z = 0; z < 11; ++z)
        for (int y = 0; y < 11; ++y)
            for (int x = 0; x < 11; ++x) {
                double best = 1e9;
                for (int a = 0; a < 3; ++a)
                    for (int s = -1; s <= 1; s += 2) {
                        Vec3d p{{5, 5, 5}};
                        p[a] += 0.5 * s;
                        best = std::min(best, length(Vec3d{{double(x), double(y), double(z)}} - p));
                    }
                const double expect = (x == 5 && y == 5 && z == 5) ? -best : best;
                ASSERT_NEAR(e.at(0, x, y, z), expect, 1e-5);
            }
}

TEST(SdfDegenerate, SurfaceTouchingBorder) {
    const Vec3i res{{20, 20, 10}};
    Field3D d = sphere_density(res, cube_box(res, 1), {{0.0, 0.0, 0.0}}, 9.0);
    Field3D e = sdf_from_density_edt(d, {});
    Field3D b = sdf_brute_force(d, {});
    const SdfError err = compare_sdf(e, b);
    EXPECT_EQ(err.sign_mismatches, 0u);
    EXPECT_LT(err.max_abs_voxels, 1e-4);
    EXPECT_LT(e.at(0, 0, 0, 0), 0);
}

// The same shape at voxel sizes 1 mm .. 1 km gives the same SDF in voxels.
TEST(SdfDegenerate, ExtremeVoxelSizes) {
    const Vec3i res{{16, 16, 16}};
    Field3D unit = random_blobs(res, {{1, 1, 1}}, 7);
    Field3D ref = sdf_from_density_edt(unit, {});
    for (double h : {1e-3, 1.0, 8.0, 1e3}) {
        Field3D d(res, 1, cube_box(res, h));
        std::copy(unit.channel(0).begin(), unit.channel(0).end(), d.channel(0).begin());
        for (int m = 0; m < 2; ++m) {
            Field3D e = m == 0 ? sdf_from_density_edt(d, {}) : sdf_from_density_fast_sweeping(d, {});
            expect_all_finite(e);
            double worst = 0;
            for (size_t i = 0; i < e.voxel_count(); ++i) {
                ASSERT_EQ(e.channel(0)[i] < 0, ref.channel(0)[i] < 0);
                if (m == 0) worst = std::max(worst, std::abs(e.channel(0)[i] / h - ref.channel(0)[i]));
            }
            EXPECT_LT(worst, 1e-4) << "h " << h;
        }
    }
}

TEST(SdfErrors, NanDensityNamesTheVoxel) {
    Field3D d({{4, 4, 4}}, 1, cube_box({{4, 4, 4}}, 1));
    d.at(0, 1, 2, 3) = std::numeric_limits<float>::quiet_NaN();
    try {
        sdf_from_density_edt(d, {});
        FAIL() << "expected an error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("voxel (1, 2, 3)"), std::string::npos) << e.what();
    }
    EXPECT_THROW(sdf_from_density_fast_sweeping(d, {}), Error);
    SdfOptions o;
    o.channel = 3;
    EXPECT_THROW(sdf_from_density_edt(Field3D({{4, 4, 4}}, 1, cube_box({{4, 4, 4}}, 1)), o), Error);
}

TEST(SdfEdt, SameBytesForAnyThreadCount) {
    Field3D d = random_blobs({{64, 48, 32}}, {{1, 1, 1}}, 11, 9);
    Field3D one = [&] {
        tbb::global_control gc(tbb::global_control::max_allowed_parallelism, 1);
        return sdf_from_density_edt(d, {});
    }();
    Field3D many = sdf_from_density_edt(d, {});
    EXPECT_TRUE(one == many);
}

// Grids one voxel thin in some axes (2D and 1D slabs) and a single voxel.
TEST(SdfDegenerate, ThinGrids) {
    for (Vec3i res : {Vec3i{{1, 1, 1}}, Vec3i{{7, 1, 1}}, Vec3i{{1, 9, 1}}, Vec3i{{6, 5, 1}}, Vec3i{{1, 4, 6}}}) {
        Field3D d = random_blobs(res, {{2, 2, 2}}, 5, 3);
        for (bool border : {false, true}) {
            SdfOptions o;
            o.iso = 0.3;
            o.border_is_outside = border;
            const Field3D e = sdf_from_density_edt(d, o);
            const Field3D b = sdf_brute_force(d, o);
            const SdfError err = compare_sdf(e, b);
            EXPECT_EQ(err.sign_mismatches, 0u);
            EXPECT_LT(err.max_abs_voxels, 1e-4) << res[0] << "x" << res[1] << "x" << res[2];
            expect_all_finite(e);
        }
    }
}

// OpenVDB's sweep ignores neighbour distances >= 1000 world units; Atlas must
// still give every distance the grid holds. A 40^3 grid of 40 m voxels (1.6 km
// side) with a small cloud in one corner: the far field reaches ~2.5 km.
TEST(SdfFastSweeping, FarFieldBeyond1000mMatchesBruteForce) {
    const Vec3i res{{40, 40, 40}};
    const double h = 40;
    const Field3D d = sphere_density(res, cube_box(res, h), {{220, 260, 180}}, 130);
    for (double far : {0.0, 1e6}) {
        SdfOptions o;
        o.far_distance = far; // a large far_distance must not change distances where there is a surface
        const Field3D fs = sdf_from_density_fast_sweeping(d, o);
        o.border_is_outside = true;
        const Field3D ref = sdf_brute_force(d, o);
        float ref_max = 0, fs_max = 0;
        for (size_t i = 0; i < ref.voxel_count(); ++i) ref_max = std::max(ref_max, ref.channel(0)[i]), fs_max = std::max(fs_max, fs.channel(0)[i]);
        ASSERT_GT(ref_max, 2000.0f) << "the test grid must reach far beyond 1000 m";
        const SdfError err = compare_sdf(fs, ref);
        EXPECT_EQ(err.sign_mismatches, 0u);
        // First order: the error grows with the distance from a small cloud
        // (measured 0.3 voxel within 400 m, 1.5 voxels at 2 km; max 1.57, rms 0.83).
        EXPECT_LT(err.max_abs_voxels, 2.0) << "far " << far << ": max " << err.max_abs_m << " m, fast sweeping max distance " << fs_max;
        EXPECT_LT(err.rms_voxels, 1.0) << "far " << far;
        uint64_t beyond = 0;
        for (size_t i = 0; i < ref.voxel_count(); ++i) beyond += ref.channel(0)[i] > 1000.0f;
        EXPECT_GT(beyond, ref.voxel_count() / 2);
        // The EDT honours the same range exactly.
        const SdfError eerr = compare_sdf(sdf_from_density_edt(d, o), ref);
        EXPECT_LT(eerr.max_abs_voxels, 1e-3);
    }
    // The same grid at 1 m voxels (all distances below 1000): the sweep is
    // homogeneous in the voxel size, so the 40 m result is 40x the 1 m one.
    Field3D unit(res, 1, cube_box(res, 1));
    std::copy(d.channel(0).begin(), d.channel(0).end(), unit.channel(0).begin());
    const Field3D a = sdf_from_density_fast_sweeping(d, {}), b = sdf_from_density_fast_sweeping(unit, {});
    for (size_t i = 0; i < a.voxel_count(); ++i) ASSERT_NEAR(a.channel(0)[i] / h, b.channel(0)[i], 1e-4 * (1 + std::abs(b.channel(0)[i]))) << i;
    // No surface: far_distance everywhere, however large.
    Field3D empty(res, 1, cube_box(res, h));
    SdfOptions o;
    o.far_distance = 1e6;
    const Field3D none = sdf_from_density_fast_sweeping(empty, o);
    for (float v : none.channel(0)) ASSERT_EQ(v, 1e6f);
}

// A grid whose diagonal exceeds 1000 voxels (the cap in index units too), at
// 10 m voxels: distances up to ~12 km, against brute force.
TEST(SdfFastSweeping, LongGridBeyond1000VoxelsMatchesBruteForce) {
    const Vec3i res{{1200, 3, 3}};
    Field3D d(res, 1, cube_box(res, 10));
    for (int z = 0; z < 3; ++z)
        for (int y = 0; y < 3; ++y)
            for (int x = 0; x < 4; ++x) d.at(0, x, y, z) = x < 3 ? 1.0f : 0.25f;
    const Field3D fs = sdf_from_density_fast_sweeping(d, {});
    SdfOptions o;
    o.border_is_outside = true;
    const Field3D ref = sdf_brute_force(d, o);
    EXPECT_GT(ref.at(0, 1199, 1, 1), 11000.0f);
    const SdfError err = compare_sdf(fs, ref);
    EXPECT_EQ(err.sign_mismatches, 0u);
    EXPECT_LT(err.max_abs_voxels, 2.0) << "max " << err.max_abs_m << " m; at the far end " << fs.at(0, 1199, 1, 1) << " vs " << ref.at(0, 1199, 1, 1);
}


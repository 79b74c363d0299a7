#include "atlas/core/error.h"
#include "atlas/volume/edit.h"
#include "atlas/volume/mesh_voxelize.h"
#include "atlas/volume/shapes.h"
#include "volume_test_util.h"

#include <gtest/gtest.h>

#include <bit>
#include <tbb/global_control.h>

#include <cmath>
#include <numbers>
#include <limits>

using namespace atlas;
using namespace atlas::volume;

namespace {
Box3d box(double s) { return {{{0, 0, 0}}, {{s, s, s}}}; }
Shape sphere(Vec3d c, double r) { Shape s; s.kind = ShapeKind::Sphere; s.a = c; s.radius = r; return s; }
} // namespace

TEST(Shapes, ExactDistances) {
    Shape b;
    b.kind = ShapeKind::Box;
    b.a = {{0, 0, 0}};
    b.half_size = {{2, 3, 4}};
    b.radius = 0;
    EXPECT_NEAR(shape_distance(b, {{5, 0, 0}}), 3, 1e-12);
    EXPECT_NEAR(shape_distance(b, {{5, 7, 0}}), 5, 1e-12);
    EXPECT_NEAR(shape_distance(b, {{0, 0, 0}}), -2, 1e-12);
    Shape c;
    c.kind = ShapeKind::Capsule;
    c.a = {{0, 0, 0}};
    c.b = {{10, 0, 0}};
    c.radius = 1;
    EXPECT_NEAR(shape_distance(c, {{5, 3, 0}}), 2, 1e-12);
    EXPECT_NEAR(shape_distance(c, {{-3, 0, 4}}), 4, 1e-12);
    EXPECT_NEAR(shape_distance(sphere({{1, 1, 1}}, 2), {{1, 1, 4}}), 1, 1e-12);
    Shape bad = sphere({{0, 0, 0}}, -1);
    EXPECT_THROW(validate_shape(bad), Error);
    EXPECT_THROW(parse_shape_kind("cone"), Error);
}

// Sphere minus sphere: the SDF CSG and the density cutout are exact at every voxel.
TEST(Cutout, SphereMinusSphereIsExact) {
    const Vec3i res{{40, 40, 40}};
    const Shape a = sphere({{20.3, 19.8, 20.1}}, 12), b = sphere({{29.1, 20.2, 21.7}}, 8);
    const Field3D sa = shape_sdf(a, res, box(40));
    const Field3D cut = subtract_shape_sdf(sa, b);
    const Field3D dens = cutout_density(density_from_sdf(sa), b);
    for (int z = 0; z < 40; ++z)
        for (int y = 0; y < 40; ++y)
            for (int x = 0; x < 40; ++x) {
                const Vec3d p = cut.voxel_center(x, y, z);
                const double da = shape_distance(a, p), db = shape_distance(b, p);
                ASSERT_EQ(cut.at(0, x, y, z), std::max(float(da), float(-db)));
                const bool in = da < 0 && db > 0;
                ASSERT_EQ(cut.at(0, x, y, z) < 0, in);
                const float expect = db > 0 ? float(std::clamp(0.5 - double(float(da)), 0.0, 1.0)) : 0.0f;
                ASSERT_EQ(dens.at(0, x, y, z), expect);
            }
    // A soft edge ramps over `edge` metres.
    const Field3D soft = cutout_density(density_from_sdf(sa), b, 4.0);
    const Field3D base = density_from_sdf(sa);
    int ramp = 0;
    for (int z = 0; z < 40; ++z)
        for (int y = 0; y < 40; ++y)
            for (int x = 0; x < 40; ++x) {
                const double db = shape_distance(b, soft.voxel_center(x, y, z));
                const double k = std::clamp(db / 4, 0.0, 1.0);
                ASSERT_NEAR(soft.at(0, x, y, z), base.at(0, x, y, z) * k, 1e-6);
                ramp += k > 0 && k < 1 && base.at(0, x, y, z) > 0;
            }
    EXPECT_GT(ramp, 100);
}

TEST(Cutout, BySdfField) {
    const Vec3i res{{24, 24, 24}};
    const Shape a = sphere({{12, 12, 12}}, 9), b = sphere({{16, 12, 12}}, 5);
    const Field3D dens = density_from_sdf(shape_sdf(a, res, box(24)));
    const Field3D by_field = cutout_density_by_sdf(dens, shape_sdf(b, res, box(24)));
    const Field3D by_shape = cutout_density(dens, b);
    EXPECT_TRUE(by_field == by_shape);
}

TEST(Composite, OperatorsExactOnAlignedGrids) {
    const Vec3i res{{24, 24, 24}};
    const Field3D w = density_from_sdf(shape_sdf(sphere({{10, 12, 12}}, 7), res, box(24)));
    const Field3D c = density_from_sdf(shape_sdf(sphere({{15, 12, 12}}, 6), res, box(24)));
    for (const char* name : {"max", "add", "over", "subtract"}) {
        const CompositeOp op = parse_composite_op(name);
        const Field3D r = composite(w, c, op, 0.75);
        for (size_t i = 0; i < w.voxel_count(); ++i) {
            const float a = w.channel(0)[i], b = 0.75f * c.channel(0)[i];
            float e = 0;
            switch (op) {
            case CompositeOp::Max: e = std::max(a, b); break;
            case CompositeOp::Add: e = a + b; break;
            case CompositeOp::Over: e = b + a * (1 - std::clamp(b, 0.0f, 1.0f)); break;
            case CompositeOp::Subtract: e = std::max(a - b, 0.0f); break;
            }
            ASSERT_EQ(r.channel(0)[i], e) << name;
        }
    }
    EXPECT_THROW(parse_composite_op("multiply"), Error);
}

// A small cloud grid placed inside a big world grid, voxels aligned.
TEST(Composite, CloudIntoWorldAtOffset) {
    Field3D world({{64, 64, 16}}, 1, {{{0, 0, 0}}, {{512, 512, 128}}});
    const Field3D cloud = density_from_sdf(shape_sdf(sphere({{136, 140, 64}}, 24), {{16, 16, 16}}, {{{96, 96, 0}}, {{224, 224, 128}}}));
    const Field3D r = composite(world, cloud, CompositeOp::Max);
    // World voxel (16, 16, 8) is at (132, 132, 68); the cloud's voxel (4, 4, 8).
    EXPECT_NEAR(r.at(0, 16, 16, 8), cloud.at(0, 4, 4, 8), 1e-5);
    EXPECT_EQ(r.at(0, 2, 2, 2), 0.0f); // outside the cloud grid: empty
}

TEST(Transform, TranslateByWholeVoxelsIsExactShift) {
    const Field3D f = atlas::volume::test::random_blobs({{16, 16, 16}}, {{1, 1, 1}}, 3);
    CloudTransform t;
    t.translate = {{3, -2, 1}};
    const Field3D g = transform_field(f, t, f.resolution(), f.bounds());
    for (int z = 1; z < 15; ++z)
        for (int y = 0; y < 13; ++y)
            for (int x = 3; x < 16; ++x) ASSERT_NEAR(g.at(0, x, y, z), f.at(0, x - 3, y + 2, z - 1), 1e-5);
}

TEST(Transform, RotateScaleSquash) {
    const Vec3i res{{40, 40, 40}};
    const Vec3d c{{20, 20, 20}};
    Shape b;
    b.kind = ShapeKind::Box;
    b.a = c;
    b.half_size = {{10, 4, 4}};
    b.radius = 0;
    const Field3D f = density_from_sdf(shape_sdf(b, res, box(40)));
    CloudTransform t;
    t.pivot = c;
    t.rotate_deg = {{0, 0, 90}};
    const Field3D r = transform_field(f, t, res, box(40));
    // 90 degrees about z: the long axis becomes y.
    for (int z = 0; z < 40; ++z)
        for (int y = 0; y < 40; ++y)
            for (int x = 0; x < 40; ++x) ASSERT_NEAR(r.at(0, x, y, z), f.at(0, 39 - y, x, z), 1e-4);
    // Scale 1.5 of a sphere: inside where the scaled sphere is (away from the edge).
    const Field3D s0 = density_from_sdf(shape_sdf(sphere(c, 8), res, box(40)));
    CloudTransform sc;
    sc.pivot = c;
    sc.scale = {{1.5, 1.5, 1.5}};
    const Field3D s1 = transform_field(s0, sc, res, box(40));
    CloudTransform sq;
    sq.pivot = c;
    sq.squash = 0.5;
    const Field3D s2 = transform_field(s0, sq, res, box(40));
    double vol0 = 0, vol2 = 0;
    for (int z = 0; z < 40; ++z)
        for (int y = 0; y < 40; ++y)
            for (int x = 0; x < 40; ++x) {
                const double rr = length(s1.voxel_center(x, y, z) - c);
                if (rr < 12 - 1.6) { ASSERT_GT(s1.at(0, x, y, z), 0.5f); }
                if (rr > 12 + 1.6) { ASSERT_LT(s1.at(0, x, y, z), 0.5f); }
                vol0 += s0.at(0, x, y, z);
                vol2 += s2.at(0, x, y, z);
            }
    EXPECT_NEAR(vol2 / vol0, 1.0, 0.05); // squash keeps the volume
    EXPECT_GT(s2.at(0, 20, 20 + 10, 20), 0.5f); // wider in y: 8 * sqrt(2) = 11.3
    EXPECT_LT(s2.at(0, 20, 20, 20 + 5), 0.5f);  // flatter in z: 4
    CloudTransform bad;
    bad.scale = {{1, 0, 1}};
    EXPECT_THROW(transform_field(f, bad, res, box(40)), Error);
}

// Empty space is not sampled: every voxel equals sample_or at its inverse-mapped point,
// inside the cloud, at its edge and far from it (a small cloud in a large grid).
TEST(Transform, SkippedEmptySpaceEqualsSamplingEveryVoxel) {
    Field3D f({{48, 40, 24}}, 2, box(48));
    for (int z = 10; z < 16; ++z)
        for (int y = 12; y < 20; ++y)
            for (int x = 20; x < 27; ++x) {
                f.at(0, x, y, z) = 0.1f * float(x - 19);
                f.at(1, x, y, z) = 1.0f / float(1 + y - 11 + z);
            }
    f.at(1, 3, 5, 2) = -0.0f; // a lone negative zero counts as occupied
    CloudTransform t;
    t.pivot = {{23, 16, 13}};
    t.rotate_deg = {{10, -20, 35}};
    t.squash = 0.7;
    t.translate = {{2.5, -1.25, 0.5}};
    const Field3D g = transform_field(f, t, f.resolution(), f.bounds());
    // The same mapping, written out (transform.cpp's inverse: p = pivot + S^-1 R^T (p' - pivot - translate)).
    const double d2r = std::numbers::pi / 180;
    const double cx = std::cos(10 * d2r), sx = std::sin(10 * d2r), cy = std::cos(-20 * d2r), sy = std::sin(-20 * d2r),
                 cz = std::cos(35 * d2r), sz = std::sin(35 * d2r);
    const double R[3][3] = {{cz * cy, cz * sy * sx - sz * cx, cz * sy * cx + sz * sx},
                            {sz * cy, sz * sy * sx + cz * cx, sz * sy * cx - cz * sx},
                            {-sy, cy * sx, cy * cx}};
    const double sq = 1 / std::sqrt(0.7);
    const Vec3d S{{sq, sq, 0.7}};
    size_t nonzero = 0;
    for (int z = 0; z < 24; ++z)
        for (int y = 0; y < 40; ++y)
            for (int x = 0; x < 48; ++x) {
                const Vec3d q = g.voxel_center(x, y, z) - t.pivot - t.translate;
                Vec3d p;
                for (int i = 0; i < 3; ++i) p[i] = (R[0][i] * q[0] + R[1][i] * q[1] + R[2][i] * q[2]) / S[i] + t.pivot[i];
                for (int c = 0; c < 2; ++c) {
                    const float want = sample_or(f, c, p);
                    ASSERT_EQ(std::bit_cast<uint32_t>(g.at(c, x, y, z)), std::bit_cast<uint32_t>(want)) << x << " " << y << " " << z << " " << c;
                    nonzero += want != 0;
                }
            }
    EXPECT_GT(nonzero, 300u);
}

TEST(Erosion, NubisRemapProperties) {
    const Field3D f = density_from_sdf(shape_sdf(sphere({{32, 32, 32}}, 20), {{64, 64, 64}}, box(64)));
    ErosionOptions o;
    o.frequency = 1.0 / 8;
    o.amount = 0;
    EXPECT_TRUE(erode_by_noise(f, o) == f);
    o.amount = 0.6;
    const Field3D e = erode_by_noise(f, o);
    bool changed = false;
    for (size_t i = 0; i < f.voxel_count(); ++i) {
        ASSERT_LE(e.channel(0)[i], f.channel(0)[i]);
        ASSERT_GE(e.channel(0)[i], 0.0f);
        if (f.channel(0)[i] == 0) { ASSERT_EQ(e.channel(0)[i], 0.0f); }
        if (f.channel(0)[i] == 1) { ASSERT_EQ(e.channel(0)[i], 1.0f); } // remap keeps full density
        changed |= e.channel(0)[i] != f.channel(0)[i];
    }
    EXPECT_TRUE(changed);
    o.seed = 2;
    EXPECT_FALSE(erode_by_noise(f, o) == e);
    {
        tbb::global_control gc(tbb::global_control::max_allowed_parallelism, 1);
        o.seed = 1;
        EXPECT_TRUE(erode_by_noise(f, o) == e);
    }
    o.amount = 2;
    EXPECT_THROW(erode_by_noise(f, o), Error);
    o.amount = 0.5;
    o.frequency = 0;
    EXPECT_THROW(erode_by_noise(f, o), Error);
}

// Empty voxels are skipped (the noise is evaluated over each row's occupied span):
// a voxel of a sparse field erodes exactly as in the full field, empty ones stay +0.
TEST(Erosion, SparseRowsErodeAsInTheFullField) {
    const Field3D full = density_from_sdf(shape_sdf(sphere({{32, 32, 32}}, 20), {{64, 64, 64}}, box(64)));
    ErosionOptions o;
    o.frequency = 1.0 / 8;
    o.amount = 0.6;
    o.octaves = 3;
    const Field3D ref = erode_by_noise(full, o);
    Field3D sparse = full;
    for (size_t i = 0; i < sparse.voxel_count(); ++i)
        if ((i * 2654435761u) % 7 != 0) sparse.channel(0)[i] = 0.0f; // a seventh kept, in scattered runs
    sparse.at(0, 5, 40, 31) = -0.0f;                                // a negative zero alone in its row
    const Field3D e = erode_by_noise(sparse, o);
    size_t kept = 0;
    for (size_t i = 0; i < e.voxel_count(); ++i) {
        const float in = sparse.channel(0)[i], out = e.channel(0)[i];
        if (std::bit_cast<uint32_t>(in) == 0u) {
            ASSERT_EQ(std::bit_cast<uint32_t>(out), 0u) << i;
        } else if (in == 0.0f) {
            ASSERT_EQ(out, 0.0f) << i;
        } else {
            ASSERT_EQ(std::bit_cast<uint32_t>(out), std::bit_cast<uint32_t>(ref.channel(0)[i])) << i;
            ++kept;
        }
    }
    EXPECT_GT(kept, 1000u);
}

TEST(Filters, SmoothDilateErode) {
    Field3D one({{9, 9, 9}}, 1, box(9));
    one.at(0, 4, 4, 4) = 1;
    const Field3D d = dilate(one, 2);
    const Field3D e = erode(d, 2);
    for (int z = 0; z < 9; ++z)
        for (int y = 0; y < 9; ++y)
            for (int x = 0; x < 9; ++x) {
                const bool in_cube = std::abs(x - 4) <= 2 && std::abs(y - 4) <= 2 && std::abs(z - 4) <= 2;
                ASSERT_EQ(d.at(0, x, y, z), in_cube ? 1.0f : 0.0f);
                ASSERT_EQ(e.at(0, x, y, z), one.at(0, x, y, z)); // closing of a point is the point
            }
    const Field3D s = smooth(one, 1.0);
    double sum = 0;
    for (float v : s.channel(0)) sum += v;
    EXPECT_NEAR(sum, 1.0, 1e-4); // mass kept away from the border
    EXPECT_NEAR(s.at(0, 4, 4, 4) / s.at(0, 5, 4, 4), std::exp(0.5), 1e-3);
    Field3D flat({{5, 5, 5}}, 1, box(5));
    std::fill(flat.channel(0).begin(), flat.channel(0).end(), 0.25f);
    const Field3D smoothed = smooth(flat, 2.0);
    for (float v : smoothed.channel(0)) ASSERT_NEAR(v, 0.25f, 1e-6);
    EXPECT_THROW(smooth(flat, -1), Error);
    EXPECT_THROW(dilate(flat, -1), Error);
}

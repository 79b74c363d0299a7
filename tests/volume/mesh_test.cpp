#include "atlas/core/error.h"
#include "atlas/volume/mesh_io.h"
#include "atlas/volume/mesh_voxelize.h"
#include "volume_test_util.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <filesystem>
#include <limits>
#include <random>

using namespace atlas;
using namespace atlas::volume;
using atlas::volume::test::box_mesh;
using atlas::volume::test::uv_sphere;

namespace {

Box3d grid_box(double size) { return {{{0, 0, 0}}, {{size, size, size}}}; }

// Brute-force reference: exact distance to every triangle, sign by the exact
// generalized winding number.
double closest_distance(const Mesh& m, Vec3d p) {
    double best = std::numeric_limits<double>::infinity();
    for (const auto& t : m.triangles) {
        // Sample-free exact distance via projection: reuse winding-independent math.
        const Vec3d a{{m.vertices[t[0]][0], m.vertices[t[0]][1], m.vertices[t[0]][2]}};
        const Vec3d b{{m.vertices[t[1]][0], m.vertices[t[1]][1], m.vertices[t[1]][2]}};
        const Vec3d c{{m.vertices[t[2]][0], m.vertices[t[2]][1], m.vertices[t[2]][2]}};
        // Dense barycentric search would be slow; do the standard region tests.
        const Vec3d n = cross(b - a, c - a);
        const double nn = dot(n, n);
        double d = std::numeric_limits<double>::infinity();
        if (nn > 0) {
            const Vec3d q = p - n * (dot(p - a, n) / nn);
            const double u = dot(cross(b - q, c - q), n), v = dot(cross(c - q, a - q), n), w = dot(cross(a - q, b - q), n);
            if (u >= 0 && v >= 0 && w >= 0) d = length(p - q);
        }
        auto seg = [&](Vec3d s0, Vec3d s1) {
            const Vec3d e = s1 - s0;
            const double tt = std::clamp(dot(p - s0, e) / dot(e, e), 0.0, 1.0);
            return length(p - (s0 + e * tt));
        };
        d = std::min({d, seg(a, b), seg(b, c), seg(c, a)});
        best = std::min(best, d);
    }
    return best;
}

bool analytic_sphere_inside(Vec3d p, Vec3d c, double r) { return length(p - c) < r; }

} // namespace

TEST(MeshWinding, ExactWindingNumberOfSphere) {
    const Mesh m = uv_sphere({{0, 0, 0}}, 1.0);
    EXPECT_NEAR(winding_number(m, {{0.1, 0.2, -0.3}}), 1.0, 1e-9);
    EXPECT_NEAR(winding_number(m, {{2, 0, 0}}), 0.0, 1e-9);
}

TEST(MeshWinding, WatertightVoteEqualsExactWinding) {
    const Vec3d c{{10.3, 9.7, 10.1}};
    const Mesh m = uv_sphere(c, 6.5, 16, 32);
    const Vec3i res{{20, 20, 20}};
    const Field3D w = mesh_winding_field(m, res, grid_box(20));
    for (int z = 0; z < 20; ++z)
        for (int y = 0; y < 20; ++y)
            for (int x = 0; x < 20; ++x) {
                const double exact = winding_number(m, w.voxel_center(x, y, z));
                ASSERT_NEAR(w.at(0, x, y, z), std::round(exact), 1e-6) << x << "," << y << "," << z;
            }
}

// A ray through a shared vertex or edge must count the crossing once: a box
// whose edges lie exactly on voxel-centre lines.
TEST(MeshWinding, RaysThroughEdgesAndVertices) {
    const Mesh m = box_mesh({{2.5, 2.5, 2.5}}, {{7.5, 6.5, 5.5}});
    const Field3D w = mesh_winding_field(m, {{10, 10, 10}}, grid_box(10));
    for (int z = 0; z < 10; ++z)
        for (int y = 0; y < 10; ++y)
            for (int x = 0; x < 10; ++x) {
                const bool strictly_in = x >= 3 && x <= 6 && y >= 3 && y <= 5 && z >= 3 && z <= 4;
                const bool strictly_out = x < 2 || x > 7 || y < 2 || y > 6 || z < 2 || z > 5;
                if (strictly_in) {
                    ASSERT_GT(w.at(0, x, y, z), 0.5f) << x << "," << y << "," << z;
                }
                if (strictly_out) {
                    ASSERT_LT(w.at(0, x, y, z), 0.5f) << x << "," << y << "," << z;
                }
            }
}

TEST(MeshWinding, SurvivesHoles) {
    const Vec3d c{{16.2, 15.9, 16.1}};
    const double r = 10.0;
    Mesh m = uv_sphere(c, r, 20, 40);
    // Punch holes: remove a patch of triangles and some scattered ones.
    std::mt19937 rng(4);
    for (int k = 0; k < 12; ++k) m.triangles.erase(m.triangles.begin() + long(rng() % m.triangles.size()));
    m.triangles.erase(m.triangles.begin() + 300, m.triangles.begin() + 312);
    const Field3D w = mesh_winding_field(m, {{32, 32, 32}}, grid_box(32));
    int wrong = 0;
    for (int z = 0; z < 32; ++z)
        for (int y = 0; y < 32; ++y)
            for (int x = 0; x < 32; ++x) {
                const Vec3d p = w.voxel_center(x, y, z);
                if (std::abs(length(p - c) - r) < 1.0) continue; // tessellation band
                wrong += (w.at(0, x, y, z) > 0.5f) != analytic_sphere_inside(p, c, r);
            }
    EXPECT_EQ(wrong, 0);
}

TEST(MeshWinding, SelfIntersectingUnionIsInside) {
    Mesh a = uv_sphere({{10, 12, 12}}, 6, 16, 32);
    const Mesh b = uv_sphere({{15, 12, 12}}, 6, 16, 32);
    const uint32_t off = uint32_t(a.vertices.size());
    a.vertices.insert(a.vertices.end(), b.vertices.begin(), b.vertices.end());
    for (auto t : b.triangles) a.triangles.push_back({t[0] + off, t[1] + off, t[2] + off});
    const Field3D w = mesh_winding_field(a, {{24, 24, 24}}, grid_box(24));
    // The overlap (winding 2) is inside, as is each lobe.
    EXPECT_GT(w.at(0, 12, 12, 12), 1.5f);
    EXPECT_GT(w.at(0, 6, 12, 12), 0.5f);
    EXPECT_GT(w.at(0, 18, 12, 12), 0.5f);
    EXPECT_LT(w.at(0, 1, 1, 1), 0.5f);
}

TEST(MeshRepair, FlippedDuplicateAndDegenerateTriangles) {
    const Vec3d c{{12.1, 11.8, 12.2}};
    const double r = 8;
    const Mesh clean = uv_sphere(c, r, 16, 32);
    Mesh bad = clean;
    std::mt19937 rng(9);
    int flipped = 0;
    for (auto& t : bad.triangles)
        if (rng() % 5 == 0) std::swap(t[1], t[2]), ++flipped;
    bad.triangles.push_back(bad.triangles[5]);                                   // duplicate
    bad.triangles.push_back({bad.triangles[7][0], bad.triangles[7][2], bad.triangles[7][1]}); // reversed duplicate
    bad.triangles.push_back({3, 3, 4});                                           // repeated corner
    bad.vertices.push_back(bad.vertices[10]);                                     // duplicate vertex
    bad.vertices.push_back({{float(c[0]), float(c[1]), float(c[2])}});
    bad.vertices.push_back({{float(c[0] + 1), float(c[1]), float(c[2])}});
    bad.vertices.push_back({{float(c[0] + 2), float(c[1]), float(c[2])}});       // collinear triple
    const uint32_t n = uint32_t(bad.vertices.size());
    bad.triangles.push_back({n - 3, n - 2, n - 1});
    MeshRepairReport rep;
    const Mesh fixed = repair_mesh(bad, &rep);
    EXPECT_EQ(fixed.triangles.size(), clean.triangles.size());
    EXPECT_GE(rep.flipped_triangles, uint64_t(std::min(flipped, int(clean.triangles.size()) - flipped)));
    EXPECT_GE(rep.removed_degenerate + rep.removed_duplicates, 3u);
    EXPECT_EQ(rep.components, 1u);
    EXPECT_NEAR(winding_number(fixed, c), 1.0, 1e-9);
    const Field3D w = mesh_winding_field(fixed, {{24, 24, 24}}, grid_box(24));
    int wrong = 0;
    for (int z = 0; z < 24; ++z)
        for (int y = 0; y < 24; ++y)
            for (int x = 0; x < 24; ++x) {
                const Vec3d p = w.voxel_center(x, y, z);
                if (std::abs(length(p - c) - r) < 1.0) continue;
                wrong += (w.at(0, x, y, z) > 0.5f) != analytic_sphere_inside(p, c, r);
            }
    EXPECT_EQ(wrong, 0);
    // An inside-out mesh is turned outwards.
    Mesh inverted = clean;
    for (auto& t : inverted.triangles) std::swap(t[1], t[2]);
    EXPECT_NEAR(winding_number(repair_mesh(inverted), c), 1.0, 1e-9);
}

TEST(MeshSdf, MatchesBruteForce) {
    const Vec3d c{{12.3, 11.6, 12.4}};
    const Mesh m = uv_sphere(c, 7.3, 12, 24);
    const Vec3i res{{24, 24, 24}};
    MeshSdfStats st;
    const Field3D s = mesh_to_sdf(m, res, grid_box(24), {}, nullptr, &st);
    EXPECT_GT(st.line_hits, 0u);
    double worst_band = 0, worst = 0;
    for (int z = 0; z < 24; ++z)
        for (int y = 0; y < 24; ++y)
            for (int x = 0; x < 24; ++x) {
                const Vec3d p = s.voxel_center(x, y, z);
                const double ref = (winding_number(m, p) > 0.5 ? -1 : 1) * closest_distance(m, p);
                const double got = s.at(0, x, y, z);
                ASSERT_EQ(got < 0, ref < 0) << x << "," << y << "," << z;
                const double e = std::abs(got - ref);
                (std::abs(ref) <= 1.5 ? worst_band : worst) = std::max(std::abs(ref) <= 1.5 ? worst_band : worst, e);
            }
    EXPECT_LT(worst_band, 1e-4); // exact band
    EXPECT_LT(worst, 0.5);       // documented bound beyond the band
}

TEST(MeshSdf, OpenVdbVariantSignAndError) {
    const Vec3d c{{12.3, 11.6, 12.4}};
    const Mesh m = uv_sphere(c, 7.3, 12, 24);
    const Field3D ours = mesh_to_sdf(m, {{24, 24, 24}}, grid_box(24));
    const Field3D vdb = mesh_to_sdf_openvdb(m, {{24, 24, 24}}, grid_box(48)); // 2 m voxels
    const Field3D ours2 = mesh_to_sdf(m, {{24, 24, 24}}, grid_box(48));
    for (size_t i = 0; i < vdb.voxel_count(); ++i) {
        ASSERT_EQ(vdb.channel(0)[i] < 0, ours2.channel(0)[i] < 0) << i;
        // Exact band, then first-order fast sweeping: within one voxel (2 m) here.
        ASSERT_NEAR(vdb.channel(0)[i], ours2.channel(0)[i], 2.0) << i;
    }
    (void)ours;
}

TEST(MeshSdf, ExtremeScalesAndDensity) {
    const Vec3i res{{16, 16, 16}};
    Field3D ref = mesh_to_sdf(uv_sphere({{8.2, 7.9, 8.1}}, 5, 12, 24), res, grid_box(16));
    for (double h : {1e-3, 1e3}) {
        const Mesh m = uv_sphere({{8.2 * h, 7.9 * h, 8.1 * h}}, 5 * h, 12, 24);
        const Field3D s = mesh_to_sdf(m, res, grid_box(16 * h));
        for (size_t i = 0; i < s.voxel_count(); ++i) {
            ASSERT_TRUE(std::isfinite(s.channel(0)[i]));
            ASSERT_EQ(s.channel(0)[i] < 0, ref.channel(0)[i] < 0);
            ASSERT_NEAR(s.channel(0)[i] / h, ref.channel(0)[i], 1e-3);
        }
        const Field3D d = density_from_sdf(s);
        EXPECT_EQ(d.at(0, 8, 8, 8), 1.0f);
        EXPECT_EQ(d.at(0, 0, 0, 0), 0.0f);
    }
}

TEST(MeshErrors, EmptyAndNonFinite) {
    Mesh empty;
    EXPECT_THROW(mesh_to_sdf(empty, {{4, 4, 4}}, grid_box(4)), Error);
    Mesh nan = box_mesh({{1, 1, 1}}, {{2, 2, 2}});
    nan.vertices[3][1] = std::numeric_limits<float>::quiet_NaN();
    try {
        mesh_winding_field(nan, {{4, 4, 4}}, grid_box(4));
        FAIL();
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("vertex 3"), std::string::npos) << e.what();
    }
    EXPECT_THROW(repair_mesh(nan), Error);
    Mesh bad_index = box_mesh({{1, 1, 1}}, {{2, 2, 2}});
    bad_index.triangles[0][0] = 99;
    EXPECT_THROW(mesh_to_sdf(bad_index, {{4, 4, 4}}, grid_box(4)), Error);
    EXPECT_THROW(read_mesh("/nonexistent/cloud.obj"), Error);
}

TEST(MeshIo, RoundTripEveryFormat) {
    const auto dir = std::filesystem::temp_directory_path() / ("atlas_mesh_io_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    const Mesh cube = box_mesh({{1.25, 1.5, 1.75}}, {{6.5, 6.25, 5.5}});
    const Field3D ref = mesh_winding_field(cube, {{8, 8, 8}}, grid_box(8));
    for (const char* ext : {"obj", "off", "ply", "stl"}) {
        const auto file = dir / (std::string("cube.") + ext);
        write_mesh(file, cube);
        MeshRepairReport rep;
        const Mesh back = read_mesh(file, &rep);
        EXPECT_EQ(back.triangles.size(), 12u) << ext;
        EXPECT_EQ(back.vertices.size(), 8u) << ext; // STL's unshared corners are merged
        EXPECT_TRUE(mesh_winding_field(back, {{8, 8, 8}}, grid_box(8)) == ref) << ext;
    }
    // A file with text that is not a mesh.
    const auto junk = dir / "junk.off";
    { std::FILE* f = std::fopen(junk.c_str(), "w"); std::fputs("OFF\n3 1 0\n0 0 0\n1 0 nan\n", f); std::fclose(f); }
    EXPECT_THROW(read_mesh(junk), Error);
    std::filesystem::remove_all(dir);
}

TEST(MeshSdf, SameBytesForAnyThreadCount) {
    Mesh m = uv_sphere({{16.3, 15.2, 16.8}}, 9, 16, 32);
    m.triangles.erase(m.triangles.begin() + 40, m.triangles.begin() + 46); // a hole: exercises the exact-winding fallback
    const Field3D many = mesh_to_sdf(m, {{32, 32, 32}}, grid_box(32));
    const Field3D many_w = mesh_winding_field(m, {{32, 32, 32}}, grid_box(32));
    tbb::global_control gc(tbb::global_control::max_allowed_parallelism, 1);
    EXPECT_TRUE(mesh_to_sdf(m, {{32, 32, 32}}, grid_box(32)) == many);
    EXPECT_TRUE(mesh_winding_field(m, {{32, 32, 32}}, grid_box(32)) == many_w);
}

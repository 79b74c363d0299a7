#include "atlas/core/error.h"
#include "atlas/volume/interior_fill.h"
#include "atlas/volume/mesh_primitives.h"
#include "atlas/volume/mesh_voxelize.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

using namespace atlas;
using namespace atlas::volume;

TEST(MeshPrimitives, ClosedAndOutward) {
    const Vec3d c{{5, 6, 7}};
    const Mesh meshes[] = {make_box_mesh(c, {{2, 3, 1}}), make_sphere_mesh(c, 3, 12, 24), make_torus_mesh(c, 4, 1.5, 32, 16)};
    const Vec3d inside[] = {c, c, c + Vec3d{{4, 0, 0}}};
    for (int i = 0; i < 3; ++i) {
        EXPECT_NEAR(winding_number(meshes[i], inside[i]), 1.0, 1e-9) << i;
        EXPECT_NEAR(winding_number(meshes[i], c + Vec3d{{20, 0, 0}}), 0.0, 1e-9) << i;
    }
    EXPECT_NEAR(winding_number(meshes[2], c), 0.0, 1e-9); // the torus hole
    EXPECT_THROW(make_sphere_mesh(c, -1), Error);
    EXPECT_THROW(make_torus_mesh(c, 1, 2), Error);
    EXPECT_THROW(make_box_mesh(c, {{1, 0, 1}}), Error);
}

TEST(InteriorFill, SphereSamplesInsideSizedByThickness) {
    const Vec3d c{{100, 120, 80}};
    const double r = 40;
    const Mesh m = make_sphere_mesh(c, r, 24, 48);
    InteriorFillOptions o;
    o.target_samples = 500;
    o.radius_scale = 0.9;
    InteriorFillStats st;
    const Points p = fill_mesh_interior(m, o, &st);
    ASSERT_EQ(p.positions.size(), size_t(o.target_samples)); // exact since node version 2 (interior_fill_count_test.cpp)
    EXPECT_EQ(st.samples, p.positions.size());
    EXPECT_GE(st.tetrahedra, 1u);
    double mesh_volume = 0;
    for (const auto& t : m.triangles) {
        auto v = [&](uint32_t i) { return Vec3d{{m.vertices[i][0], m.vertices[i][1], m.vertices[i][2]}}; };
        mesh_volume += dot(v(t[0]), cross(v(t[1]), v(t[2]))) / 6;
    }
    EXPECT_NEAR(st.interior_volume / mesh_volume, 1.0, 1e-6);
    const auto& rad = p.attributes.at("radius");
    const auto& th = p.attributes.at("thickness");
    const double inscribed = r * std::cos(std::numbers::pi / 24); // tessellation: faces lie inside the sphere
    for (size_t i = 0; i < p.positions.size(); ++i) {
        const Vec3d q{{p.positions[i][0], p.positions[i][1], p.positions[i][2]}};
        const double d = length(q - c);
        ASSERT_LT(d, r);
        ASSERT_GE(th[i], inscribed - d - 1e-3);
        ASSERT_LE(th[i], r - d + 1e-3);
        ASSERT_NEAR(rad[i], 0.9 * th[i], 1e-4);
    }
    // Deterministic, and the seed moves the samples.
    EXPECT_TRUE(fill_mesh_interior(m, o) == p);
    o.seed = 2;
    EXPECT_FALSE(fill_mesh_interior(m, o) == p);
}

TEST(InteriorFill, BadMeshesGiveClearErrors) {
    Mesh inverted = make_sphere_mesh({{0, 0, 0}}, 10, 8, 16);
    for (auto& t : inverted.triangles) std::swap(t[1], t[2]);
    EXPECT_THROW(fill_mesh_interior(inverted), Error);
    // Two overlapping spheres in one mesh: self-intersecting.
    Mesh a = make_sphere_mesh({{0, 0, 0}}, 10, 8, 16);
    const Mesh b = make_sphere_mesh({{5, 0, 0}}, 10, 8, 16);
    const uint32_t off = uint32_t(a.vertices.size());
    a.vertices.insert(a.vertices.end(), b.vertices.begin(), b.vertices.end());
    for (auto t : b.triangles) a.triangles.push_back({t[0] + off, t[1] + off, t[2] + off});
    try {
        fill_mesh_interior(a);
        FAIL() << "expected an error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("intersects itself"), std::string::npos) << e.what();
    }
    EXPECT_THROW(fill_mesh_interior(Mesh{}), Error);
    Mesh open = make_sphere_mesh({{0, 0, 0}}, 10, 8, 16);
    open.triangles.pop_back();
    try {
        fill_mesh_interior(open);
        FAIL() << "expected an error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("holes"), std::string::npos) << e.what();
    }
    InteriorFillOptions bad;
    bad.radius_scale = 0;
    EXPECT_THROW(fill_mesh_interior(make_box_mesh({{0, 0, 0}}, {{1, 1, 1}}), bad), Error);
}

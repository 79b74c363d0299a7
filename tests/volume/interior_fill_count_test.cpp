// volume/interior_fill honours target_samples and spreads the samples
// (issue 16: target 2000 gave 459,717 samples on the CGAL armadillo, 300 gave
// 27,822 on the elephant). Checked against independent brute force: the
// enclosed volume (divergence theorem), inside-ness (exact winding number),
// thickness (point-triangle distance over every triangle) and the spacing of
// the samples (all pairs).
#include "atlas/volume/interior_fill.h"
#include "atlas/io/geometry_files.h"
#include "atlas/volume/mesh_repair.h"
#include "volume/mesh_files.h"
#include "atlas/volume/mesh_primitives.h"
#include "atlas/volume/mesh_voxelize.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <string>
#include <unistd.h>

using namespace atlas;
using namespace atlas::volume;

namespace {

// The stated tolerance: the sample count is within 1 % of the target (it is
// exact by construction; the tolerance leaves room for a future sampler).
constexpr double kCountTolerance = 0.01;

Vec3d d3(const Vec3f& v) { return {{v[0], v[1], v[2]}}; }

double enclosed_volume(const Mesh& m) {
    double v = 0;
    for (const auto& t : m.triangles) v += dot(d3(m.vertices[t[0]]), cross(d3(m.vertices[t[1]]), d3(m.vertices[t[2]]))) / 6;
    return v;
}

// Distance from p to triangle abc (Ericson, Real-Time Collision Detection 5.1.5).
double point_triangle_distance(const Vec3d& p, const Vec3d& a, const Vec3d& b, const Vec3d& c) {
    const Vec3d ab = b - a, ac = c - a, ap = p - a;
    const double d1 = dot(ab, ap), d2 = dot(ac, ap);
    if (d1 <= 0 && d2 <= 0) return length(p - a);
    const Vec3d bp = p - b;
    const double d3_ = dot(ab, bp), d4 = dot(ac, bp);
    if (d3_ >= 0 && d4 <= d3_) return length(p - b);
    const double vc = d1 * d4 - d3_ * d2;
    if (vc <= 0 && d1 >= 0 && d3_ <= 0) return length(p - (a + ab * (d1 / (d1 - d3_))));
    const Vec3d cp = p - c;
    const double d5 = dot(ab, cp), d6 = dot(ac, cp);
    if (d6 >= 0 && d5 <= d6) return length(p - c);
    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) return length(p - (a + ac * (d2 / (d2 - d6))));
    const double va = d3_ * d6 - d5 * d4;
    if (va <= 0 && (d4 - d3_) >= 0 && (d5 - d6) >= 0) return length(p - (b + (c - b) * ((d4 - d3_) / ((d4 - d3_) + (d5 - d6)))));
    const double den = 1 / (va + vb + vc);
    return length(p - (a + ab * (vb * den) + ac * (vc * den)));
}

// Checks one fill: count, inside, thickness, spacing. `checked` samples (spread
// over the set) get the brute-force inside and thickness tests.
void check_fill(const Mesh& m, int target, const std::string& what, size_t checked = 60) {
    InteriorFillOptions o;
    o.target_samples = target;
    o.radius_scale = 0.9;
    InteriorFillStats st;
    const Points p = fill_mesh_interior(m, o, &st);
    const double n = double(p.positions.size());
    EXPECT_LE(std::abs(n - target), kCountTolerance * target) << what << ": " << n << " samples for target " << target;
    ASSERT_GT(p.positions.size(), 1u);
    const auto& th = p.attributes.at("thickness");
    const auto& rad = p.attributes.at("radius");
    const size_t stride = std::max<size_t>(1, p.positions.size() / checked);
    for (size_t i = 0; i < p.positions.size(); i += stride) {
        const Vec3d q = d3(p.positions[i]);
        EXPECT_GT(winding_number(m, q), 0.5) << what << ": sample " << i << " outside the mesh";
        double best = std::numeric_limits<double>::infinity();
        for (const auto& t : m.triangles)
            best = std::min(best, point_triangle_distance(q, d3(m.vertices[t[0]]), d3(m.vertices[t[1]]), d3(m.vertices[t[2]])));
        EXPECT_NEAR(th[i], best, 1e-4 * (1 + best)) << what << ": thickness of sample " << i;
        EXPECT_NEAR(rad[i], 0.9 * th[i], 1e-4 * (1 + th[i])) << what;
    }
    // Spread: the closest pair is at least half the spacing
    // s = (V / n)^(1/3). (n uniform-random points would have their closest
    // pair near s * n^(-1/2), 0.02 s at n = 2000; measured 0.79-0.87 s on
    // the four meshes here.)
    const double s = std::cbrt(enclosed_volume(m) / n);
    double closest = std::numeric_limits<double>::infinity();
    for (size_t i = 0; i < p.positions.size(); ++i)
        for (size_t j = i + 1; j < p.positions.size(); ++j) closest = std::min(closest, length(d3(p.positions[i]) - d3(p.positions[j])));
    EXPECT_GE(closest, 0.5 * s) << what << ": closest pair " << closest << " m, spacing " << s << " m";
}

// The CGAL demo meshes of the issue, extracted from libcgal-demo's data.tar.gz
// (scripts/setup.sh installs it) into a scratch directory.
std::filesystem::path cgal_mesh(const std::string& name) {
    const std::filesystem::path tarball = "/usr/share/doc/libcgal-demo/data.tar.gz";
    if (!std::filesystem::exists(tarball)) return {};
    const auto dir = std::filesystem::temp_directory_path() / ("atlas_interior_fill_" + std::to_string(getpid()));
    const auto file = dir / "data" / "meshes" / name;
    if (!std::filesystem::exists(file)) {
        std::filesystem::create_directories(dir);
        const std::string cmd = "tar xzf " + tarball.string() + " -C " + dir.string() + " data/meshes/" + name;
        if (std::system(cmd.c_str()) != 0) return {};
    }
    return file;
}

} // namespace

TEST(InteriorFillCount, TorusAndSphereHonourTheTarget) {
    check_fill(make_torus_mesh({{2800, 2800, 240}}, 420, 140, 64, 32), 250, "torus");
    check_fill(make_sphere_mesh({{0, 0, 0}}, 50, 24, 48), 1000, "sphere");
}

TEST(InteriorFillCount, CgalArmadilloAndElephantHonourTheTarget) {
    const auto armadillo = cgal_mesh("armadillo.off"), elephant = cgal_mesh("elephant.off");
    if (armadillo.empty() || elephant.empty()) GTEST_SKIP() << "libcgal-demo's data.tar.gz is not installed";
    check_fill(volume_nodes::read_mesh_file(elephant), 300, "elephant");
    check_fill(volume_nodes::read_mesh_file(armadillo), 2000, "armadillo", 20);
    std::error_code ec;
    std::filesystem::remove_all(armadillo.parent_path().parent_path().parent_path(), ec);
}

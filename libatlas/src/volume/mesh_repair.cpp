// Mesh validation and repair through CGAL (the files are read in io:
// atlas/io/geometry_files.h).
#include "atlas/volume/mesh_repair.h"

#include "atlas/core/error.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/repair_polygon_soup.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numeric>
#include <string>
#include <vector>

namespace atlas::volume {
namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = K::Point_3;
using Polygon = std::vector<std::size_t>;
namespace PMP = CGAL::Polygon_mesh_processing;

Vec3d to_d(const Point& p) { return {{p.x(), p.y(), p.z()}}; }

uint32_t find_root(std::vector<uint32_t>& parent, uint32_t i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
}

// Soup -> repaired triangle mesh (shared by repair_mesh and read_mesh).
Mesh repair_soup(std::vector<Point> points, std::vector<Polygon> polygons, MeshRepairReport& rep) {
    const size_t points_in = points.size();
    // Fan-triangulate polygons with more than three corners.
    std::vector<Polygon> tris;
    tris.reserve(polygons.size());
    for (const Polygon& p : polygons) {
        if (p.size() > 3) ++rep.polygons_triangulated;
        for (size_t i = 1; i + 1 < p.size(); ++i) tris.push_back({p[0], p[i], p[i + 1]});
    }
    const size_t tris_in = tris.size();
    // Merges duplicate points, drops polygons with repeated corners and
    // duplicate polygons (any orientation), removes unused points.
    PMP::repair_polygon_soup(points, tris, CGAL::parameters::erase_all_duplicates(false).require_same_orientation(false));
    rep.merged_vertices = points_in > points.size() ? points_in - points.size() : 0;
    // Collinear (zero-area) triangles: area tiny against the triangle's own
    // longest edge squared (scale-free, so one far vertex does not make every
    // other triangle "degenerate").
    const size_t before_area = tris.size();
    std::erase_if(tris, [&](const Polygon& t) {
        const Vec3d a = to_d(points[t[0]]), b = to_d(points[t[1]]), c = to_d(points[t[2]]);
        const double e2 = std::max({dot(b - a, b - a), dot(c - b, c - b), dot(a - c, a - c)});
        return length(cross(b - a, c - a)) * 0.5 <= 1e-12 * e2;
    });
    const size_t after = tris.size();
    rep.removed_degenerate = before_area - after;
    rep.removed_duplicates = tris_in > before_area ? tris_in - before_area : 0; // includes repeated-corner ones
    if (tris.empty()) throw Error("mesh: no usable triangles remain after removing degenerate ones");

    // Consistent orientation across shared edges. May duplicate non-manifold vertices.
    std::vector<Polygon> oriented = tris;
    PMP::orient_polygon_soup(points, oriented);
    for (size_t i = 0; i < oriented.size() && i < tris.size(); ++i)
        if (oriented[i] != tris[i]) ++rep.flipped_triangles;

    // Components by shared (undirected) edges; flip those with negative volume.
    std::vector<uint32_t> parent(oriented.size());
    std::iota(parent.begin(), parent.end(), 0u);
    std::map<std::pair<size_t, size_t>, uint32_t> edge_owner;
    for (uint32_t t = 0; t < oriented.size(); ++t)
        for (int e = 0; e < 3; ++e) {
            size_t a = oriented[t][size_t(e)], b = oriented[t][size_t((e + 1) % 3)];
            auto [it, fresh] = edge_owner.try_emplace({std::min(a, b), std::max(a, b)}, t);
            if (!fresh) parent[find_root(parent, t)] = find_root(parent, it->second);
        }
    std::map<uint32_t, std::vector<uint32_t>> comps;
    for (uint32_t t = 0; t < oriented.size(); ++t) comps[find_root(parent, t)].push_back(t);
    rep.components = comps.size();
    for (auto& [root, members] : comps) {
        Vec3d centroid{};
        for (uint32_t t : members)
            for (size_t v : oriented[t]) centroid = centroid + to_d(points[v]);
        centroid = centroid / double(members.size() * 3);
        double vol = 0;
        for (uint32_t t : members) {
            const Vec3d a = to_d(points[oriented[t][0]]) - centroid, b = to_d(points[oriented[t][1]]) - centroid,
                        c = to_d(points[oriented[t][2]]) - centroid;
            vol += dot(a, cross(b, c));
        }
        if (vol < 0) {
            for (uint32_t t : members) std::swap(oriented[t][1], oriented[t][2]);
            rep.flipped_triangles += members.size();
        }
    }
    Mesh out;
    out.vertices.reserve(points.size());
    for (const Point& p : points) out.vertices.push_back({{float(p.x()), float(p.y()), float(p.z())}});
    out.triangles.reserve(oriented.size());
    for (const Polygon& t : oriented) out.triangles.push_back({uint32_t(t[0]), uint32_t(t[1]), uint32_t(t[2])});
    return out;
}

} // namespace

Mesh repair_mesh(const Mesh& m, MeshRepairReport* report) {
    validate_mesh(m, "repair_mesh");
    std::vector<Point> points;
    points.reserve(m.vertices.size());
    for (const Vec3f& v : m.vertices) points.emplace_back(v[0], v[1], v[2]);
    std::vector<Polygon> polys;
    polys.reserve(m.triangles.size());
    for (const auto& t : m.triangles) polys.push_back({t[0], t[1], t[2]});
    MeshRepairReport rep;
    Mesh out = repair_soup(std::move(points), std::move(polys), rep);
    if (report) *report = rep;
    return out;
}

Mesh repair_polygon_soup(PolygonSoup soup, MeshRepairReport* report) {
    validate_polygon_soup(soup, "repair_polygon_soup");
    std::vector<Point> points;
    points.reserve(soup.points.size());
    for (const Vec3d& v : soup.points) points.emplace_back(v[0], v[1], v[2]);
    MeshRepairReport rep;
    Mesh out = repair_soup(std::move(points), std::move(soup.polygons), rep);
    if (report) *report = rep;
    return out;
}

} // namespace atlas::volume

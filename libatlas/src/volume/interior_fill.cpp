// Mesh interior fill through TetGen, sized by local thickness.
#include "atlas/volume/interior_fill.h"

#include "atlas/core/error.h"
#include "atlas/core/hash.h"
#include "atlas/volume/mesh_io.h"

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/boost/graph/helpers.h>

// The library build of TetGen throws an int instead of exiting.
#define TETLIBRARY
#include <tetgen.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

namespace atlas::volume {
namespace {
using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Triangle = K::Triangle_3;
using TriIt = std::vector<Triangle>::const_iterator;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<K, CGAL::AABB_triangle_primitive<K, TriIt>>>;

Vec3d to_d(const Vec3f& v) { return {{v[0], v[1], v[2]}}; }

// TetGen 1.5 crashes (double free while unwinding) on self-intersecting input,
// so closedness and self-intersections are checked with CGAL first.
void check_closed_and_simple(const Mesh& m) {
    namespace PMP = CGAL::Polygon_mesh_processing;
    std::vector<K::Point_3> points;
    points.reserve(m.vertices.size());
    for (const Vec3f& v : m.vertices) points.emplace_back(v[0], v[1], v[2]);
    std::vector<std::vector<std::size_t>> faces;
    faces.reserve(m.triangles.size());
    for (const auto& t : m.triangles) faces.push_back({t[0], t[1], t[2]});
    if (!PMP::is_polygon_soup_a_polygon_mesh(faces))
        throw Error("interior fill: the mesh is not a manifold surface (non-manifold edges or inconsistent orientation); run it through repair");
    CGAL::Surface_mesh<K::Point_3> sm;
    PMP::polygon_soup_to_polygon_mesh(points, faces, sm);
    if (!CGAL::is_closed(sm)) throw Error("interior fill: the mesh has holes (it must be closed)");
    if (PMP::does_self_intersect(sm)) throw Error("interior fill: the mesh intersects itself (TetGen needs a simple closed surface)");
}
} // namespace

Points fill_mesh_interior(const Mesh& m, const InteriorFillOptions& o, InteriorFillStats* stats) {
    validate_mesh(m, "interior fill");
    if (o.target_samples < 1 || o.target_samples > 10000000) throw Error("interior fill: target_samples must be in [1, 1e7]");
    if (!(o.radius_scale > 0) || !std::isfinite(o.radius_scale)) throw Error("interior fill: radius_scale must be finite and > 0");
    if (!(o.min_radius >= 0) || !std::isfinite(o.min_radius)) throw Error("interior fill: min_radius must be finite and >= 0");
    check_closed_and_simple(m);
    // Enclosed volume (divergence theorem) sets the tetrahedron size.
    double volume = 0;
    for (const auto& t : m.triangles) volume += dot(to_d(m.vertices[t[0]]), cross(to_d(m.vertices[t[1]]), to_d(m.vertices[t[2]]))) / 6;
    if (!(volume > 0)) throw Error("interior fill: the mesh encloses no volume (is it closed and facing outwards? run it through repair)");

    tetgenio in, out;
    in.firstnumber = 0;
    in.numberofpoints = int(m.vertices.size());
    in.pointlist = new REAL[m.vertices.size() * 3];
    for (size_t i = 0; i < m.vertices.size(); ++i)
        for (int a = 0; a < 3; ++a) in.pointlist[i * 3 + size_t(a)] = m.vertices[i][a];
    in.numberoffacets = int(m.triangles.size());
    in.facetlist = new tetgenio::facet[m.triangles.size()];
    for (size_t f = 0; f < m.triangles.size(); ++f) {
        tetgenio::facet& fc = in.facetlist[f];
        tetgenio::init(&fc);
        fc.numberofpolygons = 1;
        fc.polygonlist = new tetgenio::polygon[1];
        tetgenio::init(&fc.polygonlist[0]);
        fc.polygonlist[0].numberofvertices = 3;
        fc.polygonlist[0].vertexlist = new int[3];
        for (int k = 0; k < 3; ++k) fc.polygonlist[0].vertexlist[k] = int(m.triangles[f][size_t(k)]);
    }
    // p: piecewise linear complex; q: quality (radius-edge <= 2); a: max volume; Q: quiet.
    std::ostringstream sw;
    sw.precision(17);
    sw << "pq2a" << volume / o.target_samples << "Q";
    std::string switches = sw.str();
    try {
        tetrahedralize(switches.data(), &in, &out);
    } catch (int code) {
        const char* why = code == 3 ? "a self-intersection" : code == 4 ? "a very small feature" : code == 5 ? "two very close facets"
                          : code == 1 ? "out of memory" : "an input error";
        throw Error(std::string("interior fill: TetGen could not tetrahedralise the mesh (") + why +
                    "; it must be closed and free of self-intersections)");
    } catch (...) {
        throw Error("interior fill: TetGen could not tetrahedralise the mesh (it must be closed and free of self-intersections)");
    }
    if (out.numberoftetrahedra <= 0) throw Error("interior fill: TetGen produced no tetrahedra");

    std::vector<Triangle> tris;
    tris.reserve(m.triangles.size());
    for (const auto& t : m.triangles) {
        auto P = [&](uint32_t i) { return K::Point_3(m.vertices[i][0], m.vertices[i][1], m.vertices[i][2]); };
        tris.emplace_back(P(t[0]), P(t[1]), P(t[2]));
    }
    Tree tree(tris.cbegin(), tris.cend());
    tree.accelerate_distance_queries();

    Points pts;
    std::vector<float> radius, thickness;
    const size_t nt = size_t(out.numberoftetrahedra);
    const int corners = out.numberofcorners;
    double tet_volume = 0, max_thick = 0;
    for (size_t t = 0; t < nt; ++t) {
        Vec3d v[4];
        for (int k = 0; k < 4; ++k) {
            const int idx = out.tetrahedronlist[t * size_t(corners) + size_t(k)] - out.firstnumber;
            v[k] = {{out.pointlist[idx * 3], out.pointlist[idx * 3 + 1], out.pointlist[idx * 3 + 2]}};
        }
        tet_volume += std::abs(dot(v[1] - v[0], cross(v[2] - v[0], v[3] - v[0]))) / 6;
        // Uniform point in the tetrahedron (Rocchini & Cignoni folding of the unit cube).
        double s = hash_to_unit(hash_coords(o.seed, int32_t(t), 0)), u = hash_to_unit(hash_coords(o.seed, int32_t(t), 1)),
               w = hash_to_unit(hash_coords(o.seed, int32_t(t), 2));
        if (s + u > 1) s = 1 - s, u = 1 - u;
        if (u + w > 1) { const double tmp = w; w = 1 - s - u; u = 1 - tmp; }
        else if (s + u + w > 1) { const double tmp = w; w = s + u + w - 1; s = 1 - u - tmp; }
        const Vec3d p = v[0] + (v[1] - v[0]) * s + (v[2] - v[0]) * u + (v[3] - v[0]) * w;
        const double th = std::sqrt(tree.squared_distance(K::Point_3(p[0], p[1], p[2])));
        max_thick = std::max(max_thick, th);
        pts.positions.push_back({{float(p[0]), float(p[1]), float(p[2])}});
        thickness.push_back(float(th));
        radius.push_back(float(std::max(o.min_radius, th * o.radius_scale)));
    }
    pts.attributes["radius"] = std::move(radius);
    pts.attributes["thickness"] = std::move(thickness);
    if (stats) {
        stats->tetrahedra = nt;
        stats->interior_volume = tet_volume;
        stats->max_thickness = max_thick;
    }
    return pts;
}

} // namespace atlas::volume

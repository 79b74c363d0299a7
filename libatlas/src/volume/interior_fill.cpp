// Mesh interior fill through TetGen, sized by local thickness.
#include "atlas/volume/interior_fill.h"

#include "atlas/core/error.h"
#include "atlas/core/hash.h"
#include "atlas/volume/mesh_repair.h"

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
#include <array>
#include <limits>
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

// Candidates per sample for the farthest-point selection, and the sample
// count above which the selection (n x candidates distance updates) is
// skipped and the candidates are the samples.
constexpr size_t kCandidatesPerSample = 8;
constexpr size_t kSpreadLimit = 20000;

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
    // p: piecewise linear complex (constrained Delaunay of the surface, no
    // Steiner points for quality: the tetrahedra only carry the volume we
    // draw from, so the fewest is the cheapest); Q: quiet.
    std::string switches = "pQ";
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

    // Tetrahedra and their cumulative volume: candidates are drawn uniformly
    // in the interior (a tet by volume, a point uniform in it).
    const size_t nt = size_t(out.numberoftetrahedra);
    const int corners = out.numberofcorners;
    std::vector<std::array<Vec3d, 4>> tets(nt);
    std::vector<double> cum(nt);
    double tet_volume = 0;
    for (size_t t = 0; t < nt; ++t) {
        for (int k = 0; k < 4; ++k) {
            const int idx = out.tetrahedronlist[t * size_t(corners) + size_t(k)] - out.firstnumber;
            tets[t][size_t(k)] = {{out.pointlist[idx * 3], out.pointlist[idx * 3 + 1], out.pointlist[idx * 3 + 2]}};
        }
        const auto& v = tets[t];
        tet_volume += std::abs(dot(v[1] - v[0], cross(v[2] - v[0], v[3] - v[0]))) / 6;
        cum[t] = tet_volume;
    }
    const size_t n = size_t(o.target_samples);
    const size_t ncand = n <= kSpreadLimit ? std::max<size_t>(n * kCandidatesPerSample, 64) : n;
    std::vector<Vec3d> cand(ncand);
    for (size_t i = 0; i < ncand; ++i) {
        const int32_t ii = int32_t(i);
        // 48-bit uniform from two hashes: a tet by volume.
        const double r = (double(hash_coords(o.seed, ii, 3) >> 8) + double(hash_coords(o.seed, ii, 4) >> 8) / 16777216.0) / 16777216.0;
        const size_t t = std::min(nt - 1, size_t(std::upper_bound(cum.begin(), cum.end(), r * tet_volume) - cum.begin()));
        const auto& v = tets[t];
        // Uniform point in the tetrahedron (Rocchini & Cignoni folding of the unit cube).
        double s = hash_to_unit(hash_coords(o.seed, ii, 0)), u = hash_to_unit(hash_coords(o.seed, ii, 1)), w = hash_to_unit(hash_coords(o.seed, ii, 2));
        if (s + u > 1) s = 1 - s, u = 1 - u;
        if (u + w > 1) { const double tmp = w; w = 1 - s - u; u = 1 - tmp; }
        else if (s + u + w > 1) { const double tmp = w; w = s + u + w - 1; s = 1 - u - tmp; }
        cand[i] = v[0] + (v[1] - v[0]) * s + (v[2] - v[0]) * u + (v[3] - v[0]) * w;
    }
    // Farthest-point selection of exactly n of the candidates: each new sample
    // is the candidate farthest from every sample taken so far, so the samples
    // are evenly spread (no two closer than about half the spacing
    // (volume / n)^(1/3)) and become separate puffs, not a uniform-random fuzz.
    std::vector<size_t> chosen;
    chosen.reserve(n);
    if (ncand == n) {
        for (size_t i = 0; i < n; ++i) chosen.push_back(i);
    } else {
        std::vector<double> d2(ncand, std::numeric_limits<double>::infinity());
        size_t next = 0;
        for (size_t k = 0; k < n; ++k) {
            chosen.push_back(next);
            const Vec3d c = cand[next];
            double best = -1;
            size_t arg = 0;
            for (size_t i = 0; i < ncand; ++i) {
                const Vec3d d = cand[i] - c;
                d2[i] = std::min(d2[i], dot(d, d));
                if (d2[i] > best) best = d2[i], arg = i;
            }
            next = arg;
        }
    }

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
    double max_thick = 0;
    for (size_t i : chosen) {
        const Vec3d p = cand[i];
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
        stats->candidates = ncand;
        stats->samples = pts.positions.size();
        stats->interior_volume = tet_volume;
        stats->max_thickness = max_thick;
    }
    return pts;
}

} // namespace atlas::volume

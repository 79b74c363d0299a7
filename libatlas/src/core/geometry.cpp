#include "atlas/core/geometry.h"

#include "atlas/core/error.h"
#include "atlas/core/hash.h"

#include <cmath>
#include <cstdio>

namespace atlas {

void Mesh::hash_into(Hasher& h) const {
    h.add("Mesh");
    h.add_bytes(vertices.data(), vertices.size() * sizeof(Vec3f));
    h.add_bytes(triangles.data(), triangles.size() * sizeof(triangles[0]));
}

void Points::hash_into(Hasher& h) const {
    h.add("Points");
    h.add_bytes(positions.data(), positions.size() * sizeof(Vec3f));
    for (const auto& [name, values] : attributes) h.add(name).add_floats(values);
}

uint64_t Points::byte_size() const {
    uint64_t n = positions.size() * sizeof(Vec3f);
    for (const auto& kv : attributes) n += kv.second.size() * sizeof(float);
    return n;
}

namespace {

// One coordinate of vertex i: finite and within +-kMaxMeshCoordinate.
void check_vertex_coordinate(double v, size_t i, int axis, const std::string& who) {
    if (std::isfinite(v) && std::abs(v) <= kMaxMeshCoordinate) return;
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.9g", v);
    throw Error(who + ": vertex " + std::to_string(i) + " has " + "xyz"[axis] + " = " + buf +
                (std::isfinite(v) ? ", outside the supported range +-1e18 m" : ", which is not finite"));
}

} // namespace

void validate_polygon_soup(const PolygonSoup& soup, const std::string& who) {
    for (size_t i = 0; i < soup.points.size(); ++i)
        for (int a = 0; a < 3; ++a) check_vertex_coordinate(soup.points[i][a], i, a, who);
    for (size_t f = 0; f < soup.polygons.size(); ++f) {
        const auto& poly = soup.polygons[f];
        if (poly.size() < 3)
            throw Error(who + ": face " + std::to_string(f) + " has " + std::to_string(poly.size()) + " corners, expected at least 3");
        for (size_t v : poly)
            if (v >= soup.points.size())
                throw Error(who + ": face " + std::to_string(f) + " uses vertex " + std::to_string(v) + " but there are " +
                            std::to_string(soup.points.size()) + " vertices");
    }
}

void validate_mesh(const Mesh& m, const std::string& who) {
    if (m.triangles.empty()) throw Error(who + ": the mesh has no triangles");
    for (size_t i = 0; i < m.vertices.size(); ++i)
        for (int a = 0; a < 3; ++a) check_vertex_coordinate(m.vertices[i][a], i, a, who);
    for (size_t t = 0; t < m.triangles.size(); ++t)
        for (uint32_t v : m.triangles[t])
            if (v >= m.vertices.size())
                throw Error(who + ": triangle " + std::to_string(t) + " uses vertex " + std::to_string(v) + " but the mesh has " +
                            std::to_string(m.vertices.size()));
}

} // namespace atlas

// atlas/core/geometry.h - Mesh and Points values (world space, metres).
#pragma once

#include "atlas/core/math.h"

#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace atlas {

class Hasher;

// Triangle mesh. Indices are 0-based into `vertices`.
struct Mesh {
    std::vector<Vec3f> vertices;
    std::vector<std::array<uint32_t, 3>> triangles;

    void hash_into(Hasher& h) const;
    bool operator==(const Mesh&) const = default;
    uint64_t byte_size() const { return vertices.size() * sizeof(Vec3f) + triangles.size() * sizeof(triangles[0]); }
};

// A point set with optional per-point float attributes (e.g. "radius"),
// each the same length as `positions`.
struct Points {
    std::vector<Vec3f> positions;
    std::map<std::string, std::vector<float>> attributes;

    void hash_into(Hasher& h) const;
    bool operator==(const Points&) const = default;
    uint64_t byte_size() const;
};

// Polygons as a mesh file holds them, before repair (volume::repair_polygon_soup
// makes a Mesh of it): double positions, polygons of 3 or more 0-based corners.
struct PolygonSoup {
    std::vector<Vec3d> points;
    std::vector<std::vector<size_t>> polygons;
};

// Largest |coordinate| (metres) of a mesh vertex or a grid bound that readers
// and the mesh code accept. Distances then stay below ~3.5e18 m; beyond
// ~1.8e19 m their squares overflow float.
inline constexpr double kMaxMeshCoordinate = 1e18;

// Throws atlas::Error starting "who: " when a point is NaN, infinite or beyond
// +-kMaxMeshCoordinate (naming its index and coordinate), a polygon has fewer
// than 3 corners, or a corner names a point that does not exist.
void validate_polygon_soup(const PolygonSoup& soup, const std::string& who);

// The same for a triangle mesh, plus: throws when it has no triangles. Both
// share one vertex check, so readers and the mesh algorithms word it alike.
void validate_mesh(const Mesh& mesh, const std::string& who = "mesh");

using MeshPtr = std::shared_ptr<const Mesh>;
using PointsPtr = std::shared_ptr<const Points>;

} // namespace atlas

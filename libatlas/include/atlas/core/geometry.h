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

using MeshPtr = std::shared_ptr<const Mesh>;
using PointsPtr = std::shared_ptr<const Points>;

} // namespace atlas

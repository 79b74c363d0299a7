#include "atlas/core/geometry.h"

#include "atlas/core/hash.h"

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

} // namespace atlas

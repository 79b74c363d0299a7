// Internal: crossings of a mesh with the grid lines through voxel centres.
#pragma once

#include "atlas/core/field.h"
#include "atlas/core/geometry.h"

#include <cstdint>
#include <vector>

namespace atlas::volume::detail {

// Hits of the lines along one axis. Line id = i_b + i_c * res[b] with (b, c)
// the other two axes in increasing order. Per line, hits sorted by t.
struct AxisHits {
    std::vector<uint32_t> offsets;   // lines + 1 entries (CSR)
    std::vector<double> t;           // position along the axis in voxel index units (centres at integers)
    std::vector<int8_t> sign;        // +1: the surface faces against +axis (entering), -1: along
};

struct MeshLineHits {
    AxisHits axis[3];
    uint64_t total = 0;
};

// Throws via validate_mesh on unusable meshes.
MeshLineHits mesh_line_hits(const Mesh& mesh, Vec3i res, Box3d bounds);

// Mean of the six axis-ray winding counts per voxel (flat index, x fastest).
// Where the six counts disagree (a ray passed a hole or a flipped face), and
// the total cost (disagreeing voxels x triangles) is at most
// kExactWindingBudget, the mean is replaced by the exact generalized winding
// number at the voxel centre. `exact_used` (optional) receives the count.
inline constexpr double kExactWindingBudget = 2e9;
std::vector<float> ray_winding_vote(const MeshLineHits& hits, Vec3i res, const Mesh& mesh, Box3d bounds,
                                    uint64_t* exact_used = nullptr);

// Other axes of `a` in increasing order.
inline void other_axes(int a, int& b, int& c) {
    b = a == 0 ? 1 : 0;
    c = a == 2 ? 1 : 2;
}

} // namespace atlas::volume::detail

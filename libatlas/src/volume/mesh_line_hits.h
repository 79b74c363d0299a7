// Internal: crossings of a mesh with the grid lines through voxel centres.
#pragma once

#include "atlas/core/field.h"
#include "atlas/core/geometry.h"

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
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

// Fast generalized winding number (Barill, Dickson, Schmidt, Levin and
// Jacobson 2018, "Fast winding numbers for soups and clouds"): a bounding
// volume hierarchy over the triangles; a node farther than beta x its radius
// from the query contributes its first-order (dipole) term, nearer nodes are
// opened and their triangles' exact solid angles summed. Cost per query
// O(log triangles) for far queries; absolute error < 0.02 in the tests (beta 3; measured 0.012).
// Deterministic (fixed traversal order); thread-safe to query.
class FastWindingNumber {
public:
    explicit FastWindingNumber(const Mesh& mesh, double beta = 3.0);
    double operator()(const Vec3d& q) const;

private:
    struct Node {
        Vec3d centre;      // area-weighted centroid of the node's triangles
        Vec3d area_normal; // sum of area x unit normal
        double radius;     // max distance from centre to a corner
        uint32_t begin, end, left; // triangle range; left child (right = left + 1); left == 0: leaf
    };
    std::vector<Node> nodes_;
    std::vector<std::array<Vec3d, 3>> corners_; // triangles in tree order
    double beta_;
};

// Mean of the six axis-ray winding counts per voxel (flat index, x fastest).
// Where the six counts disagree (a ray passed a hole or a flipped face), the
// mean is replaced by the generalized winding number at the voxel centre
// (FastWindingNumber). `fallback_voxels` (optional) receives how many.
std::vector<float> ray_winding_vote(const MeshLineHits& hits, Vec3i res, const Mesh& mesh, Box3d bounds,
                                    uint64_t* fallback_voxels = nullptr);

// The union's surface: which triangles bound the union of the mesh's
// overlapping parts. A surface point lies on the union's boundary when the
// point just beyond it (along its outward normal) is outside, i.e. the
// generalized winding number there is <= 0.5. Triangles that cross another
// triangle (sharing no vertex with it) are "straddling": part of them may be
// buried, and their intersection segments (which are on the union's boundary)
// are kept. Others are wholly on the surface or wholly buried.
struct UnionSurface {
    enum State : uint8_t { kSurface = 0, kBuried = 1, kStraddling = 2 };
    std::vector<uint8_t> state;                                      // per triangle; empty: all kSurface
    std::vector<std::vector<std::array<Vec3d, 2>>> segments;         // per triangle (straddling only)
    std::vector<std::array<uint8_t, 3>> corner_buried;               // per triangle (straddling only)
    std::unique_ptr<FastWindingNumber> winding;                      // set when any triangle straddles
    double eps = 0;                                                  // offset for the "just beyond" tests, metres
    uint64_t buried = 0, straddling = 0, components = 0;
    bool trivial() const { return state.empty(); }
    // Is the point q of triangle t buried (strictly inside another part)?
    bool point_buried(const Mesh& mesh, uint32_t t, const Vec3d& q) const;
};
UnionSurface union_surface(const Mesh& mesh);

// Squared distance from p to the unburied part of straddling triangle ti: its closest
// point if unburied, else the nearest unburied corner, edge point or intersection
// segment point (+inf when none); that point in `closest` when given. Both mesh SDF
// methods use it.
double straddling_squared_distance(const Mesh& mesh, const UnionSurface& us, uint32_t ti, const Vec3d& p,
                                   Vec3d* closest = nullptr);

// Hits whose inside state (count > 0.5, from both ends of the line) does not
// change across them are interior to the union (a surface crossing inside
// another part): not distance seeds. Returns the t of the kept hits of line l.
void union_boundary_hits(const AxisHits& ah, uint32_t l, std::vector<double>& out);

// The whole grid (res voxels, x fastest) of signed distances, in `out`, for both mesh SDF
// methods: the exact EDT to the seeds (union-boundary crossings with the grid lines),
// lowered by the exact band, signed by the six-ray vote (inside: all six counts >= 1;
// where they differ, the fast winding number > 0.5). `band(sq)` is called once with `out`
// holding squared distances (m^2, +inf where none) that are upper bounds: it lowers them
// (min) with its exact ones, and may run in parallel. Distance `far` where there is no seed.
// Returns the number of voxels whose six counts disagreed. Same bytes for any thread count.
uint64_t mesh_signed_distance(const MeshLineHits& hits, const UnionSurface& us, const Mesh& mesh, Vec3i res, Box3d bounds,
                              float far, float* out, const std::function<void(float* sq)>& band);

// Other axes of `a` in increasing order.
inline void other_axes(int a, int& b, int& c) {
    b = a == 0 ? 1 : 0;
    c = a == 2 ? 1 : 2;
}

} // namespace atlas::volume::detail

// Internal: the far field of the `edt` mesh SDF method, refined by flooding the exact band's
// closest surface points outwards (closest-point propagation).
//
// Beyond the exact band, mesh_signed_distance gives the distance to the nearest crossing of
// the surface with a grid line. Near a convex tip lying between grid lines that crossing is
// off to one side of the tip, and the over-estimate (about the offset projected on the
// viewing direction) does not decay with distance. Each voxel of the band's outer layer
// knows its exact closest surface point c; carrying c outwards, voxel to voxel, gives each
// voxel reached the distance to a real surface point (so never short) that is near the
// true closest one.
#pragma once

#include "atlas/core/geometry.h"

#include <cstdint>
#include <vector>

namespace atlas::volume::detail {

// A voxel (flat index, x fastest) of the exact band's outer layer and its exact closest
// point on the surface (metres).
struct ClosestPointSeed {
    uint64_t voxel;
    Vec3d point;
};

// Tolerance of the flood (voxels, of the smallest voxel edge): a voxel takes a carried
// point only if that lowers its distance by more than this. Chosen by measurement on the
// CGAL armadillo at 256^3 (docs/PERFORMANCE.md, 2026-12-04): at 0.2 the flood lowers 0.35 M
// voxels in 0.04 s and leaves 0.26 voxel near the band, 0.29 beyond; 0.1 is 0.19 / 0.21
// but lowers 1.6 M voxels (0.16 s); 0.25 leaves 0.35 near the band.
constexpr double kFloodToleranceVoxels = 0.2;

// Lowers |out| (signed distances, res voxels over bounds, cell-centred) by closest-point
// propagation from the seeds: a FIFO, seeds first in the given order; for each voxel taken
// with its point c, each of its 26 neighbours n whose |out[n]| exceeds |centre(n) - c| by
// more than tau_voxels (x the smallest voxel edge) takes |centre(n) - c|, its sign kept,
// and is queued with c. Serial: the same bytes whatever the thread count. Returns the
// number of voxels lowered (with repeats).
uint64_t flood_closest_points(float* out, Vec3i res, Box3d bounds, const std::vector<ClosestPointSeed>& seeds,
                              double tau_voxels = kFloodToleranceVoxels);

} // namespace atlas::volume::detail

// Shared by the volume nodes (not a node): the world-grid parameters.
#pragma once

#include "atlas/graph/node.h"

namespace atlas::volume_nodes {

// resolution / bounds_min / bounds_max, defaulting to the Nubis cloudscape:
// 4 km x 4 km x 512 m at 8 m voxels.
inline void declare_grid(NodeDeclaration& d, Vec3i res = {{512, 512, 64}}) {
    d.param_int3("resolution", res).range(1, 65536).with_unit("voxels").describe("voxels along x, y, z");
    d.param_float3("bounds_min", {{0, 0, 0}}).with_unit("m").describe("world-space minimum corner");
    d.param_float3("bounds_max", {{4096, 4096, 512}}).with_unit("m").describe("world-space maximum corner");
}

inline Box3d grid_bounds(const CookContext& ctx) {
    Box3d box{ctx.get_float3("bounds_min"), ctx.get_float3("bounds_max")};
    if (!box.valid()) ctx.fail("bounds_max must be greater than bounds_min in every axis");
    return box;
}

inline void check_grid_memory(const CookContext& ctx, Vec3i res, int fields) {
    ctx.check_memory(field_bytes(uint64_t(res[0]) * uint64_t(res[1]) * uint64_t(res[2]), fields), "the volume grids");
}

} // namespace atlas::volume_nodes

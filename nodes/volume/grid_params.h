// Shared by the volume nodes (not a node): the world-grid parameters.
#pragma once

#include "atlas/graph/node.h"
#include "common/grid.h"

namespace atlas::volume_nodes {

// resolution / bounds_min / bounds_max (nodes/common/grid.h), by default the
// Nubis cloudscape: 4 km x 4 km x 512 m at 8 m voxels.
inline void declare_grid(NodeDeclaration& d, const grid_nodes::GridDefaults& g = grid_nodes::kCloudscapeGrid) {
    grid_nodes::declare_grid(d, g);
}
using grid_nodes::grid_bounds;

inline void check_grid_memory(const CookContext& ctx, Vec3i res, int fields) {
    ctx.check_memory(field_bytes(uint64_t(res[0]) * uint64_t(res[1]) * uint64_t(res[2]), fields), "the volume grids");
}

} // namespace atlas::volume_nodes

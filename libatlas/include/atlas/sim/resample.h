// atlas/sim/resample.h - a field on the solver's grid: what the cloud-growth
// node does with its emitter and initial-state inputs.
//
// Pure, deterministic; errors are atlas::Error.
#pragma once

#include "atlas/core/field.h"
#include "atlas/sim/mac_grid.h"

#include <vector>

namespace atlas::sim {

// Channel `c` of `e` at the cell centres of grid `s` whose minimum corner is
// at world `origin`: copied cell by cell when the cells line up (same size,
// offset by whole cells), else trilinear; 0 outside the field. Along a
// periodic axis (s.periodic) a cell also sees the field through its periodic
// images (centre + m L, L the grid's length), the values of every image inside
// the field added, so a field reaching over a periodic face wraps around.
// Throws when the channel holds NaN or Inf, naming it.
std::vector<float> resample_to_grid(const Field3D& e, int c, const GridSpec& s, const Vec3d& origin);

} // namespace atlas::sim

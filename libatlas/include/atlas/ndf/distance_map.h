// atlas/ndf/distance_map.h - 3D Euclidean distance map above a heightfield.
//
// Voxel (x, y, k) of a res.x x res.y x layers grid over [z0, z1] metres is
// solid when its centre height <= h(x, y). The output holds, for every voxel,
// the Euclidean distance in metres from its centre to the nearest solid voxel
// centre (0 inside the solid; `max_distance` when there is no solid).
// Exact EDT by three 1D lower-envelope-of-parabolas sweeps (Felzenszwalb &
// Huttenlocher), linear time per row, anisotropic voxel sizes. Deterministic.
#pragma once

#include "atlas/core/field.h"
#include "atlas/core/memory.h"

namespace atlas::ndf {

Field3D distance_map(const Field2D& heights, int channel, int layers, double z0, double z1, double max_distance,
                     const MemoryBudget* budget);

// O(N^2) reference for tests.
Field3D distance_map_brute_force(const Field2D& heights, int channel, int layers, double z0, double z1, double max_distance);

} // namespace atlas::ndf

// atlas/volume/projection.h - a 2D view of a volume for previews.
#pragma once

#include "atlas/core/field.h"

namespace atlas::volume {

// Optical-depth style projection along z: out(x, y) = 1 - exp(-k * sum_z d(x, y, z) * dz)
// with dz the voxel height (metres) and k = extinction (1/m, > 0). A density of
// 1 over 100 m with k = 0.01 gives 1 - e^-1. Channel "opacity"; bounds = the
// field's x/y bounds. Deterministic (each column summed in z order).
Field2D project_density(const Field3D& density, double extinction = 0.01, int channel = 0);

} // namespace atlas::volume

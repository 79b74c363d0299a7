// atlas/ndf/bake.h - 2.5D authoring data baked into a 3D dimensional profile.
//
// For a voxel at world (x, y, z) with the NDF set sampled bilinearly at (x, y)
// (clamped) and f = (z - min_height) / (max_height - min_height):
//   VerticalProfile: dp = coverage * bottom(bottom_type, f) * top(top_type, f)
//   Envelope:        dp = coverage * f^2 * (1 - f)^1.5   (Nubis Evolved:
//                    bottom * top * edge, the coverage as the edge gradient)
// and dp = 0 outside 0 <= f <= 1 or when max_height <= min_height.
// Output: 1 channel "dimensional_profile". Pure, deterministic.
#pragma once

#include "atlas/core/field.h"
#include "atlas/core/memory.h"
#include "atlas/ndf/vertical_profile.h"

namespace atlas::ndf {

enum class BakeFormula { VerticalProfile, Envelope };

// The per-point formula (what the bake evaluates per voxel).
double bake_formula(BakeFormula formula, const VerticalProfile& profile, double coverage, double top_type, double bottom_type,
                    double min_height, double max_height, double z);

Field3D bake_ndf_set(const Field2D& set, BakeFormula formula, const VerticalProfile& profile, Vec3i res, Box3d bounds,
                     const MemoryBudget* budget);

} // namespace atlas::ndf

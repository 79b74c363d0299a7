// atlas/ndf/cone_map.h - cone-step maps for the envelope method.
//
// The heightfield is a grid of box columns: texel (x, y) is solid from -inf
// up to h(x, y) metres over its square footprint. A cone with apex at height a
// over a footprint region and ratio c (horizontal / vertical, both metres)
// contains no solid when for every texel s with h(s) > a:
//   dist(region, square(s)) >= c * (h(s) - a).
// Ratios are capped at `max_ratio` (flat areas would be infinite); capping
// only narrows cones, so it stays conservative.
#pragma once

#include "atlas/core/field.h"
#include "atlas/core/memory.h"
#include "atlas/core/progress.h"

namespace atlas::ndf {

struct ConeMapOptions {
    double texel_size = 1;   // metres per texel (square texels; use the smaller side)
    double max_ratio = 1e4;  // cap for cones that never hit anything
    // false: exact conservative cones (apex at the texel's own height over its
    // own square) for point/nearest sampling. true: robust cones for bilinear
    // sampling (see cone_map_robust).
    bool robust = false;
};

// Brute force, O(N^4): the reference. 1 channel "cone_ratio" (exact mode) or
// 2 channels "apex_height", "cone_ratio" (robust mode).
Field2D cone_map_brute_force(const Field2D& heights, int channel, const ConeMapOptions& opt, const MemoryBudget* budget);

// Same values, bit for bit, via branch-and-bound over a max-mip pyramid:
// a node of the pyramid is skipped when dist(region, node) / (max - a) cannot
// beat the best ratio found (Valasek & Ban's max-mip idea); near nodes first.
// About N^2 log N on natural heightfields. Parallel over rows, deterministic.
Field2D cone_map(const Field2D& heights, int channel, const ConeMapOptions& opt, const MemoryBudget* budget,
                 const ProgressSink* progress = nullptr);

// Robust mode, why: a renderer that filters (apex, ratio) bilinearly can get a
// wide cone on a low apex (the failure the 2024 robust cone step mapping work
// shows). Here texel t stores apex_height = max of h over its 5x5
// neighbourhood and cone_ratio valid for an apex at max h over its 3x3
// neighbourhood anywhere in the square of side 2 texels centred on t (every
// point whose bilinear lookup uses t). A bilinear apex is then >= every
// contributing texel's 3x3 apex, each contributing cone is valid at the lookup
// point, and a convex combination of ratios is <= the largest valid one.
//
// Marching (both modes): at (p, z) with z >= apex, direction (d_xy, d_z),
// |d_xy| = 1, d_z < 0, the step s = c (z - apex) / (1 - c d_z) stays in the cone.
double cone_step_length(double ratio, double z, double apex, double dz);

} // namespace atlas::ndf

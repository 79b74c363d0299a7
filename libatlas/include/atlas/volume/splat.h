// atlas/volume/splat.h - density from points: metaballs, spheres, particle splats.
//
// Each point p with radius R (metres) adds a kernel k(r / R), r = |x - p|,
// supported on r < R, times the point's weight, into a density field:
//   metaball  (1 - s^2)^3                     (Wyvill; sums blend smoothly)
//   sphere    saturate(0.5 - (r - R) / voxel) (solid ball with a one-voxel edge;
//                                              support R + voxel)
//   linear    1 - s
//   gaussian  exp(-4.5 s^2), cut at s = 1     (sigma = R / 3)
// Blend: add (sum) or max. Deterministic for any thread count: work is split
// into z slices and each voxel sums its points in input order. Thread-safe.
#pragma once

#include "atlas/core/field.h"
#include "atlas/core/geometry.h"

#include <string>

namespace atlas {
class MemoryBudget;
}

namespace atlas::volume {

enum class SplatKernel { Metaball, Sphere, Linear, Gaussian };
enum class SplatBlend { Add, Max };

// Parses "metaball", "sphere", "linear", "gaussian" / "add", "max"; throws atlas::Error.
SplatKernel parse_splat_kernel(const std::string& name);
SplatBlend parse_splat_blend(const std::string& name);

struct SplatOptions {
    SplatKernel kernel = SplatKernel::Metaball;
    SplatBlend blend = SplatBlend::Add;
    double default_radius = 64;           // metres, when the points have no radius attribute (> 0)
    double radius_scale = 1;              // multiplies every radius (> 0)
    std::string radius_attribute = "radius";
    std::string weight_attribute = "weight"; // optional per-point multiplier
    double weight = 1;                    // multiplies every point's kernel
};

// Splats the points into a one-channel "density" field of `res` voxels over
// `bounds`. Throws atlas::Error on a non-finite position (naming the point),
// a radius <= 0 or non-finite, an attribute of the wrong length.
//
// `window` (a tiled cook's): only voxels [x0, x1) x [y0, y1) of the grid,
// as a field over the window's bounds, each voxel what the whole grid's
// holds (the same positions and the same points in the same order).
Field3D splat_points(const Points& points, Vec3i res, Box3d bounds, const SplatOptions& options,
                     const MemoryBudget* budget = nullptr, const XYWindow* window = nullptr);

} // namespace atlas::volume

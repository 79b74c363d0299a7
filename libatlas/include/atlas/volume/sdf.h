// atlas/volume/sdf.h - signed distance fields from density grids.
//
// Conventions for every function here:
// - Distances are in metres (world units), negative inside, positive outside.
// - "Inside" means density > iso (strictly). A voxel exactly at iso is outside.
// - The surface is the iso-crossing of the density, linearly interpolated along
//   the grid edges between neighbouring voxel centres ("crossing points"). The
//   exact-EDT method returns, for every voxel, the exact Euclidean distance from
//   its centre to the nearest crossing point (float rounding only). Against the
//   interpolated surface between crossing points it overestimates by less than
//   sqrt(3) voxels in the worst case (a crossing lies on an edge of the cell
//   that holds the nearest surface point); measured < 0.5 voxel on spheres,
//   shrinking with distance (docs/volumes.md, tests/volume/sdf_test.cpp).
// - The whole grid is filled (no narrow band): the renderer needs far distances.
// - A grid without any crossing (empty or full) gets +far_distance (all outside)
//   or -far_distance (all inside) everywhere, unless border_is_outside puts a
//   surface on the grid faces.
// - Deterministic: every grid line is an independent computation, so the result
//   is bit-identical for any thread count. Thread-safe: pure functions.
//
// Implemented in sdf_edt.cpp, sdf_fast_sweeping.cpp, sdf_reference.cpp (src/volume/).
#pragma once

#include "atlas/core/field.h"

#include <array>
#include <cstdint>
#include <functional>

namespace atlas {
class MemoryBudget;
struct ProgressSink;
}

namespace atlas::volume {

// Default iso levels. A density's surface is its half-way level. A
// dimensional profile (saturate(-sdf / depth) ^ exponent: 0 outside, rising
// inside) has its surface where it leaves 0; on 8-bit pack data 2/255 is the
// level that reproduces the Nubis pack's own field data best (measured on the
// real pack; 0.5 put the surface depth/2 inside). docs/volumes.md.
inline constexpr double kDensityIso = 0.5;
inline constexpr double kDimensionalProfileIso = 2.0 / 255.0;

struct SdfOptions {
    int channel = 0;        // density channel to read
    double iso = kDensityIso; // iso level: density > iso is inside
    // Distance written where the grid has no surface at all, in metres; <= 0
    // means "the diagonal of the grid's bounds".
    double far_distance = 0;
    // Treat everything outside the grid as empty: inside voxels on the border
    // then see a surface on the grid face (half a voxel beyond their centre).
    bool border_is_outside = false;
    // > 0: distances are clipped to +-max_distance metres. A voxel whose
    // nearest crossing is farther, and every voxel of a grid without a
    // surface, gets +-max_distance (far_distance is then not used). A clipped
    // SDF depends only on the density within max_distance (plus one voxel) of
    // each voxel, so it tiles byte for byte (docs/scale.md). 0: unclipped.
    double max_distance = 0;
    // For a crop of a larger grid (a tiled cook's region grown by the halo):
    // the whole grid's voxel edge (all zero: the density's own voxel size),
    // and which faces of the density are faces of the whole grid, in the
    // order -x, +x, -y, +y, -z, +z (border_is_outside puts a surface only on
    // those). The defaults are the untiled cook's.
    Vec3d grid_voxel_size{{0, 0, 0}};
    std::array<bool, 6> grid_faces{{true, true, true, true, true, true}};
};

// Measured cost and the surface found, filled by the functions below.
struct SdfStats {
    uint64_t crossings = 0; // crossing points (sub-voxel seeds) found
    double seconds = 0;     // wall time of the transform
};

// Exact Euclidean distance transform (Felzenszwalb-Huttenlocher lower
// envelopes, one pass per axis) to the sub-voxel crossing points. Handles
// anisotropic voxels. Cost O(9 N) line operations, parallel over lines.
// Throws atlas::Error when the density holds NaN (naming the voxel), when
// iso or far_distance is not finite, or when the channel does not exist.
// Output: one channel named "sdf", same resolution and bounds as the input.
Field3D sdf_from_density_edt(const Field3D& density, const SdfOptions& options, const MemoryBudget* budget = nullptr,
                             SdfStats* stats = nullptr, const ProgressSink* progress = nullptr);

// OpenVDB's fast sweeping (openvdb::tools::fogToSdf) over the whole dense grid
// (every voxel active). Requires cubic voxels (throws otherwise). The sweep
// runs in scaled index units (OpenVDB ignores neighbour distances >= 1000
// world units), so every distance the grid holds is computed, at any voxel
// size; a voxel OpenVDB leaves without a distance is an error. `sweeps` is
// fogToSdf's iteration count (>= 1). OpenVDB sees the space beyond the grid
// as its inactive background (empty), so this method always behaves as if
// border_is_outside were true (the option is ignored). Deterministic per OpenVDB's own
// guarantees (its sweeps are ordered; tested for repeatability).
Field3D sdf_from_density_fast_sweeping(const Field3D& density, const SdfOptions& options, int sweeps = 1,
                                       const MemoryBudget* budget = nullptr, SdfStats* stats = nullptr);

// Brute force reference: for each voxel the distance to the nearest crossing
// point, by checking every crossing. O(N * crossings); refuses (throws) when
// N * crossings exceeds 4e9, so use it on small grids only.
Field3D sdf_brute_force(const Field3D& density, const SdfOptions& options);

// Error of `sdf` against `reference` (same resolution), in metres and voxels
// (voxels = metres / smallest voxel edge).
struct SdfError {
    double max_abs_m = 0, rms_m = 0;
    double max_abs_voxels = 0, rms_voxels = 0;
    uint64_t sign_mismatches = 0; // voxels where the signs differ (zero counts as +)
};
SdfError compare_sdf(const Field3D& sdf, const Field3D& reference, int channel = 0);

// Eikonal residual | |grad d| - 1 | from central differences, over voxels whose
// 6 neighbours exist and where `mask(x, y, z)` is true (null: every interior
// voxel). Callers exclude the medial axis / the surface band via the mask.
struct EikonalResidual {
    double mean = 0, max = 0;
    uint64_t voxels = 0;
};
EikonalResidual eikonal_residual(const Field3D& sdf, int channel = 0, const std::function<bool(int, int, int)>& mask = {});

} // namespace atlas::volume

// atlas/volume/edit.h - editing and compositing voxel clouds.
//
// Every function returns a new field (inputs are never changed). Densities are
// cell-centred floats; sampling between voxels is trilinear; outside a source
// grid the density is 0 (empty sky). Deterministic: each output voxel depends
// only on its inputs (no reductions across voxels), so results are identical
// for any thread count. Thread-safe (pure).
//
// Implemented in composite.cpp, erosion.cpp, filters.cpp, transform.cpp (src/volume/).
#pragma once

#include "atlas/core/field.h"
#include "atlas/volume/shapes.h"

#include <cstdint>
#include <string>

namespace atlas {
class MemoryBudget;
}

namespace atlas::volume {

// A similarity-plus-squash transform of a cloud, applied about `pivot`:
//   p' = pivot + translate + R * (S * (p - pivot))
// with R = Rz * Ry * Rx (degrees, right-handed), S = diag(scale) * squash,
// squash = diag(1/sqrt(s), 1/sqrt(s), s): flattens (s < 1) or stretches
// (s > 1) vertically while keeping the volume.
struct CloudTransform {
    Vec3d translate{};
    Vec3d rotate_deg{};
    Vec3d scale{{1, 1, 1}};
    double squash = 1;
    Vec3d pivot{};
};

// Resamples `src` moved by `t` onto `res` voxels over `bounds` (trilinear, by
// inverse mapping each output voxel centre). All channels. Throws atlas::Error
// on a zero/negative/non-finite scale or squash.
Field3D transform_field(const Field3D& src, const CloudTransform& t, Vec3i res, Box3d bounds,
                        const MemoryBudget* budget = nullptr);

enum class CompositeOp {
    Max,      // max(world, cloud)
    Add,      // world + cloud
    Over,     // cloud + world * (1 - saturate(cloud))
    Subtract, // max(world - cloud, 0)
};
CompositeOp parse_composite_op(const std::string& name); // "max", "add", "over", "subtract"

// Composites `cloud` (sampled trilinearly at the world grid's voxel centres,
// channel `cloud_channel`, scaled by `opacity`) into channel `world_channel`
// of a copy of `world`. Where the grids align voxel for voxel the sample is
// the cloud's voxel value exactly.
//
// `frame` (composite, the cutouts, erode_by_noise): where the first field
// sits in the grid it is a window of (a tiled cook's crop, CookContext::frame);
// null: its own grid. Positions come from the frame, so a window's values
// are the whole grid's.
Field3D composite(const Field3D& world, const Field3D& cloud, CompositeOp op, double opacity = 1, int world_channel = 0,
                  int cloud_channel = 0, const MemoryBudget* budget = nullptr, const GridFrame* frame = nullptr);

// Cutout of a density: d' = d * saturate(shape_distance(p) / edge) (edge in
// metres; edge = 0: hard cut, d' = 0 where the voxel centre is inside the
// shape). All channels are cut.
Field3D cutout_density(const Field3D& density, const Shape& shape, double edge = 0, const MemoryBudget* budget = nullptr,
                       const GridFrame* frame = nullptr);

// CSG on a signed distance field: max(sdf, -shape) (subtract the shape).
// Exact inside the result and on its boundary; outside it is a lower bound
// of the true distance.
Field3D subtract_shape_sdf(const Field3D& sdf, const Shape& shape, int channel = 0, const MemoryBudget* budget = nullptr);

// Cutout by another signed distance field (e.g. a mesh SDF), sampled
// trilinearly at the density's voxel centres (outside the cutter's grid the
// cutter is treated as far outside): d' = d * saturate(cutter / edge).
Field3D cutout_density_by_sdf(const Field3D& density, const Field3D& cutter_sdf, double edge = 0,
                              const MemoryBudget* budget = nullptr, const GridFrame* frame = nullptr);

// Value erosion as in the Nubis sampler: with n the noise in [0, 1] at the
// voxel (fractal value noise, `octaves` >= 1, lacunarity 2, gain 0.5,
// normalised), e = amount * n and d' = saturate((d - e) / (1 - e)) (e >= 1:
// d' = 0). frequency: noise cells per metre (> 0). amount in [0, 1].
// Deterministic by seed. The noise tiles on the field's bounds when
// frequency * extent is an integer on every axis.
struct ErosionOptions {
    double amount = 0.5;
    double frequency = 1.0 / 128.0;
    int octaves = 3;
    uint32_t seed = 1;
    int channel = 0;
};
Field3D erode_by_noise(const Field3D& density, const ErosionOptions& options, const MemoryBudget* budget = nullptr,
                       const GridFrame* frame = nullptr);

// Separable Gaussian blur, sigma in voxels (>= 0; 0 = copy), radius
// ceil(3 sigma), edges clamped. All channels.
Field3D smooth(const Field3D& f, double sigma_voxels, const MemoryBudget* budget = nullptr);

// Grayscale dilation (max) / erosion (min) over a cube of (2r+1)^3 voxels,
// r >= 0 voxels, separable; outside the grid does not take part. All channels.
Field3D dilate(const Field3D& f, int radius_voxels, const MemoryBudget* budget = nullptr);
Field3D erode(const Field3D& f, int radius_voxels, const MemoryBudget* budget = nullptr);

// Trilinear sample of channel c at world p; 0 (or `outside`) beyond the grid's bounds.
float sample_or(const Field3D& f, int c, Vec3d p, float outside = 0);

} // namespace atlas::volume

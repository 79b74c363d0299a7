// atlas/volume/nvdf.h - Nubis Volume Data Fields: the modeling NVDF and the
// SDF "field data" (the files of Guerrilla's Nubis voxel cloud pack: atlas/io/nubis_pack.h).
//
// Modeling NVDF: three channels, all in [0, 1]:
//   dimensional_profile  a gradient from the cloud surface inward (below)
//   detail_type          0 = wispy, 1 = billowy noise details
//   density_scale        multiplies the up-rezzed density
// Field data: the SDF (metres) mapped linearly from [range_min, range_max]
// (default [-256, 4096] m) to [0, 1] and clamped.
// Pure and deterministic; thread-safe.
#pragma once

#include "atlas/core/field.h"
#include "atlas/io/nubis_pack.h"

#include <string>
#include <vector>

namespace atlas {
class MemoryBudget;
}

namespace atlas::volume {

// The pack's SDF range, metres (a property of its files: io/nubis_pack.h).
using io::kNubisSdfMax;
using io::kNubisSdfMin;

// Dimensional profile from a signed distance field (metres, negative inside):
//   dp = saturate(-sdf / depth) ^ exponent
// 0 at and outside the surface, 1 at `depth` metres (> 0) inside and deeper.
// exponent > 0 shapes the ramp (1 = linear). Channel "dimensional_profile".
struct DimensionalProfileOptions {
    double depth = 64;   // metres
    double exponent = 1; // > 0
    int channel = 0;     // SDF channel
};
Field3D dimensional_profile(const Field3D& sdf, const DimensionalProfileOptions& options = {}, const MemoryBudget* budget = nullptr);

// SDF metres -> [0, 1] (clamped), channel "field_data"; range_max > range_min.
Field3D encode_field_data(const Field3D& sdf, double range_min = kNubisSdfMin, double range_max = kNubisSdfMax, int channel = 0,
                          const MemoryBudget* budget = nullptr);
// [0, 1] -> metres, channel "sdf".
Field3D decode_field_data(const Field3D& encoded, double range_min = kNubisSdfMin, double range_max = kNubisSdfMax, int channel = 0,
                          const MemoryBudget* budget = nullptr);

// Which channel of each input assemble_modeling_nvdf reads.
struct ModelingChannels {
    int dimensional_profile = 0, detail_type = 0, density_scale = 0;
};
// The three modeling channels in one field (same resolution and bounds; the
// channel of each input that `channels` names). Throws atlas::Error when the
// grids differ or a channel does not exist (naming the input).
Field3D assemble_modeling_nvdf(const Field3D& dimensional_profile, const Field3D& detail_type, const Field3D& density_scale,
                               const MemoryBudget* budget = nullptr, const ModelingChannels& channels = {});

// One NVDF set turning into another (issue 43: a cloudscape blending into
// another over a time range): every channel is a (1 - t) + b t, but a channel
// named "sdf" is the distance to the union of both clouds, min(a, b), for
// 0 < t < 1 (a's at t <= 0, b's at t >= 1): the blended cloud lies where
// either does, and the renderer's empty-space skipping must never step over
// it (a blended distance could). t is clamped to [0, 1]. Throws atlas::Error
// when the grids (resolution, bounds) or the channel names differ.
Field3D blend_nvdf(const Field3D& a, const Field3D& b, double t, const MemoryBudget* budget = nullptr);

} // namespace atlas::volume

// atlas/render/lights.h - optional light sources inside or near the clouds:
// point lights (internal glow) and probability-field lights (lightning
// flashes), after Schneider's GDC 2022 superstorm talk, where the glow and
// the intra-cloud flashes are lights whose position comes from a field and a
// flash index ("fed a variable position for each flash").
//
// Units: positions in world metres (z up), colours linear RGB. All types are
// plain values; the functions are pure and thread-safe.
#pragma once

#include "atlas/core/field.h"

#include <cstdint>
#include <string>
#include <vector>

namespace atlas::render {

// An isotropic point light. The light arriving at distance r is
//   colour * intensity * window(r) / (r^2 + core^2)
// (inverse square; core = half the cloud's smallest voxel keeps it finite
// at the light itself), attenuated by the density between the sample and
// the light (docs/render.md, "Point lights").
//   intensity  >= 0, finite (e.g. 1e4 lights a cloud ~100 m around it
//              about as brightly as the default sun)
//   radius     metres, >= 0; 0 = unlimited reach, else a smooth cut-off
//              window(r) = (1 - (r / radius)^4)^2 for r < radius, 0 beyond,
//              so far samples skip the light entirely
struct PointLight {
    Vec3d position{{0, 0, 0}};
    Vec3f colour{{1, 1, 1}};
    double intensity = 1;
    double radius = 0;
};

// Lights whose positions a probability field picks, one set per flash.
//   probability  a 3D field over world space; channel `channel` holds, per
//                voxel, the relative probability (>= 0) that a flash starts
//                there (NaN, Inf and negative values count as 0)
//   seed, flash  flash `flash` places `count` lights: each draws a voxel with
//                probability proportional to its value and a uniform point
//                inside it, from hash_coords(seed, flash, i, ...); the same
//                seed and flash always give the same positions, a new flash
//                index new ones (time -> flash index is the caller's choice)
//   colour, intensity, radius  as PointLight, for every light of the flash
// An all-zero field gives no light.
struct LightField {
    Field3DPtr probability;
    int channel = 0;
    Vec3f colour{{0.75f, 0.8f, 1.0f}};
    double intensity = 1;
    double radius = 0;
    uint32_t seed = 1;
    int32_t flash = 0;
    int count = 1; // 0..4096
};

// The point lights of one flash of `field`, in draw order. Throws
// atlas::Error naming the parameter (missing field, channel out of range,
// count outside 0..4096, colour/intensity/radius invalid as for
// PointLight). Single pass over the field after a sort of `count` draws:
// O(voxels + count log count), no per-voxel table.
std::vector<PointLight> flash_lights(const LightField& field);

// Throws atlas::Error naming `what` and the problem when a light's values are
// out of range (non-finite position, negative or non-finite colour,
// intensity or radius).
void validate_light(const PointLight& light, const std::string& what);

} // namespace atlas::render

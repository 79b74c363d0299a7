// atlas/ndf/cirrus.h - cirrus textures for a 2D sky layer (Far Cry 6, GDC 2022:
// a tileable cirrus hemisphere texture and a 2048x128 horizon texture mapped
// as a cylinder; three cirrus looks in one texture, one per channel, as
// Horizon Zero Dawn did).
//
// Built from the noise library (atlas/noise, sample_noise): every lookup is
// at a tile-unit coordinate, so the textures tile exactly. Streaks run along
// an integer lattice direction (a, b): the coordinates (a x + b y, -b x + a y)
// of a tiling texture still tile, which a free angle would not. Pure,
// thread-safe, deterministic for any thread count (rows are independent).
// Bad parameters throw atlas::Error naming the parameter.
#pragma once

#include "atlas/core/field.h"
#include "atlas/core/memory.h"

#include <cstdint>
#include <string>
#include <vector>

namespace atlas::ndf {

struct CirrusSpec {
    Vec2i resolution{{512, 512}};   // texels, [1, 16384] per axis
    Vec2i streak_direction{{1, 0}}; // integer lattice vector the streaks run along (not 0,0; |a|,|b| <= 16)
    int period = 4;                 // [1, 256] base lattice cells across the texture (size of the largest features)
    int stretch = 6;                // [1, 64] streak length / width of the cirrus and cirrostratus looks
    double warp = 0.04;             // [0, 1] domain-warp displacement, in texture widths
    uint32_t seed = 0;
    Box2d bounds{{{0, 0}}, {{1, 1}}}; // world box the texture covers (one tile); any valid box, e.g. a 60 km map for the Unity cloud layer
};

// Channel names: cirrostratus, cirrus, cirrocumulus.
//   cirrostratus  a wide, soft veil with faint streaks: a stretched gradient
//                 FBM, broad and low in contrast
//   cirrus        fibrous streaks: a stretched, strongly warped ridged FBM,
//                 thinned by a patch noise (sparse, high contrast)
//   cirrocumulus  billowy puffs: inverted-F1 Worley cells at 8x the period,
//                 isotropic, in patches
// Values in [0, 1] (opacity).
const std::vector<std::string>& cirrus_channels();
Field2D cirrus_texture(const CirrusSpec& spec, const MemoryBudget* budget);

struct CirrusHorizonSpec {
    Vec2i resolution{{2048, 128}}; // texels: x = azimuth (tiles), y = elevation (row 0 at the horizon)
    int cells_along = 24;          // [1, 4096] noise cells around the cylinder
    double cells_up = 4;           // (0, 1024] noise cells over the strip's height (few: flat, wide clouds)
    double fade_start = 0.35;      // [0, 1) height fraction where the fade to 0 at the top starts
    double warp = 0.01;            // [0, 1] horizontal warp, in strip lengths
    uint32_t seed = 0;
};

// One channel "cirrus_horizon" in [0, 1]: layered stretched cirrus, denser
// toward the horizon (many overlapping clouds seen edge-on) and fading to 0
// at the top row: value *= 1 - smoothstep(fade_start, 1, v), v = (y + 0.5) / H.
// Tiles along x only (x wraps around the cylinder).
Field2D cirrus_horizon(const CirrusHorizonSpec& spec, const MemoryBudget* budget);

} // namespace atlas::ndf

// atlas/ndf/three_clouds.h - an NDF set in the layout @takram/three-clouds reads.
//
// @takram/three-clouds (three.js volumetric clouds in the HZD/Nubis family)
// draws up to four cloud layers, each a fixed altitude and height with one
// channel of a tileable "local weather" texture, eroded by a 128^3 shape
// volume and a 32^3 detail volume (one channel each) and distorted by a 2D
// turbulence texture (docs/web.md gives its formulas and how Atlas's are
// mapped onto them). Here:
//
//   weather   RGBA, one channel per cloud type of the set: R stratus (type 0),
//             G stratocumulus (1/3), B cumulus (2/3), A cumulonimbus (1).
//             channel_k = coverage * saturate(2 (1 - |3 type - k|)): a texel
//             between two types is in both layers with its whole coverage
//             in the middle half of the interval. Bounds of the set.
//   layers    per type: altitude and height spanning the heights where the
//             profile LUT's bottom * top of that type is at least half its
//             largest value (where Atlas's clouds are) in the set's envelope (the
//             coverage-weighted mean min_height / max_height), and the
//             shape-altering bias that puts three-clouds' round profile's
//             peak at the LUT's peak.
//   shape     the preview's base shape (HZD's Perlin-Worley dilated by the
//             Worley FBM), equalised: value = fraction of the texture below
//             it, so three-clouds' remap(d, 1 - shape, 1) passes a fraction d
//             of the volume, as Atlas's coverage threshold does.
//   detail    the detail noise's Worley FBM (0.625, 0.25, 0.125).
//   turbulence RGB: R 0.5 (no vertical push), G/B the curl's east/north.
//
// Volumes keep Atlas's axes (x east, y north, z up); the writer orders them
// for the engine. Pure, thread-safe, deterministic; errors are atlas::Error.
#pragma once

#include "atlas/core/field.h"
#include "atlas/core/memory.h"

#include <array>
#include <string>

namespace atlas::ndf {

struct ThreeCloudsLayer {
    char channel = 'r';       // r, g, b, a
    const char* name = "";    // stratus, stratocumulus, cumulus, cumulonimbus
    double type = 0;          // the set's type this layer draws
    double altitude = 0;      // m, the layer's bottom (the set's height origin)
    double height = 0;        // m
    double shape_altering_bias = 0.35;
    bool used = false;        // some texel has coverage in this channel
};

struct ThreeCloudsWeather {
    Field2D weather; // RGBA as above
    std::array<ThreeCloudsLayer, 4> layers;
    // The envelope three-clouds draws everywhere (its layers have one
    // altitude): coverage-weighted mean min_height / max_height, and the
    // largest distance of a covered texel's own from them (0 for a set with
    // one envelope, as the shipped graphs write).
    double min_height = 0, max_height = 0;
    double envelope_spread = 0;
};

// The set's channels are found by name: coverage, min_height, max_height
// (type optional, 0 without). Throws when one of those is missing, on a
// profile LUT without bottom/top channels, or a set with no covered texel
// whose max_height > min_height.
ThreeCloudsWeather three_clouds_weather(const Field2D& set, const Field2D& profile_lut, const MemoryBudget* budget);

// The equalised dilated base shape of a 4-channel base noise (noise/hzd_set
// low: Perlin-Worley, 3 Worley FBMs); one channel "shape" in [0, 1].
Field3D three_clouds_shape(const Field3D& base_noise, const MemoryBudget* budget);

// The detail noise's Worley FBM, one channel "detail" (3+ channels in).
Field3D three_clouds_shape_detail(const Field3D& detail_noise, const MemoryBudget* budget);

// The turbulence texture from a 2-channel curl field in [0, 1].
Field2D three_clouds_turbulence(const Field2D& curl, const MemoryBudget* budget);

// The shape-altering bias b with which three-clouds' profile
// 1 - (2 eta^b - 1)^2 peaks at height fraction `peak` in (0, 1).
double three_clouds_bias_for_peak(double peak);

} // namespace atlas::ndf

// atlas/noise/recipes.h - the production noise sets, shared by graph files
// and the benchmark so both build exactly the same recipe.
//
// All fields tile exactly (one tile per field), are deterministic for any
// thread count, and hold values in [0, 1]. Bounds are the unit box.
#pragma once

#include "atlas/core/field.h"
#include "atlas/core/memory.h"
#include "atlas/core/progress.h"
#include "atlas/noise/noise_spec.h"

#include <array>
#include <cstdint>

namespace atlas::noise {

// The four NoiseSpecs of the Nubis³ voxel cloud noise (channels r, g, b, a):
// low- and high-frequency Curly-Alligator (wisps), low- and high-frequency
// Alligator (billows), each normalised to the full 0..1 range.
std::array<NoiseSpec, 4> nubis_noise_specs(uint32_t seed);

// size^3 voxels x 4 channels (Nubis: size 128). size in [1, 1024].
Field3D make_nubis_noise(int size, uint32_t seed, const ProgressSink* progress = nullptr, const MemoryBudget* budget = nullptr);

// Horizon Zero Dawn set (GPU Pro 7 ch. 4):
//   low:  low_size^3 RGBA: Perlin-Worley, then inverted-Worley FBMs at
//         periods 4, 8, 16 (3 octaves each)
//   high: high_size^3 RGB: inverted-Worley FBMs at periods 8, 16, 32
//   curl: curl_size^2 RG: 2D curl noise remapped from [-range, range] to [0, 1]
struct HzdNoise {
    Field3D low;
    Field3D high;
    Field2D curl;
};
std::array<NoiseSpec, 4> hzd_low_specs(uint32_t seed);
std::array<NoiseSpec, 3> hzd_high_specs(uint32_t seed);
NoiseSpec hzd_curl_spec(uint32_t seed);
HzdNoise make_hzd_noise(int low_size, int high_size, int curl_size, uint32_t seed, const ProgressSink* progress = nullptr,
                        const MemoryBudget* budget = nullptr);

} // namespace atlas::noise

// atlas/noise/value_fbm.h - fractal (FBM) sums of tileable value noise: the one FBM of the library.
//
// An FBM row is out[i] = sum_o w_o * value_noise(x0_o + i dx_o, y_o, z_o, period_o, seed_o)
// with octave weights w_o = gain^o / sum_k gain^k (so the sum stays in [0, 1]) and octave
// seeds seed + o * seed_step. Where each octave's samples sit on the lattice is the caller's
// choice (FbmRow), so one implementation serves the noise/value node (octave o spans
// period << o cells across the grid), the 2D NDF noise and the volume erosion (octave o at
// frequency << o over the field's extent). Deterministic and thread-safe (pure functions of
// their arguments); the parallel fills split the work in fixed rows (atlas/core/parallel.h).
#pragma once

#include "atlas/core/math.h"

#include <cstdint>
#include <span>
#include <vector>

namespace atlas {
class Field3D;
}

namespace atlas::noise {

struct ValueFbm {
    int octaves = 4;            // number of octaves, 1..16
    double gain = 0.5;          // amplitude ratio between successive octaves, [0, 1]
    uint32_t seed = 0;          // octave o uses seed + o * seed_step
    uint32_t seed_step = 1013u; // decorrelates the octaves' lattices

    // Throws atlas::Error naming the field when octaves or gain is out of range.
    void validate() const;
};

// w_o = gain^o / sum_k gain^k, o = 0..octaves-1 (as floats; they sum to 1 up to rounding).
std::vector<float> fbm_weights(const ValueFbm& f);

// Where octave o's row of samples sits: sample i at lattice (x0 + (first + i) dx, y, z), tiling period.
struct FbmRow {
    double x0 = 0, dx = 1, y = 0, z = 0;
    int64_t first = 0; // sample i sits at x0 + (first + i) dx (a window of a longer row)
    Vec3i period{{1, 1, 1}};
};

// Fills out with one FBM row; place(o) returns octave o's FbmRow. weights = fbm_weights(f);
// scratch is a reusable buffer (resized here). Values in [0, 1] up to float rounding.
template <class Place>
void value_fbm_row(std::span<float> out, const ValueFbm& f, std::span<const float> weights, Place&& place,
                   std::vector<float>& scratch);

// A grid of res voxels whose octave o spans period << o lattice cells per axis (voxel
// centres at (i + 0.5) / res * (period << o)): tiles exactly across the grid. Writes
// channel `channel` of out (resolution res), in [0, 1] up to float rounding.
void fill_value_fbm(Field3D& out, int channel, Vec3i period, const ValueFbm& f);

// The 2D version on the z = 0 lattice plane: a res[0] x res[1] map (row-major, x fastest)
// whose octave o spans period << o cells per axis. Coarse octaves (at most 4 lattice cells
// per texel) blend lattice rows once per row instead of per texel: the same noise up to
// float rounding (a few 1e-7), much faster. Not clamped.
void value_fbm_map(std::span<float> out, Vec2i res, Vec2i period, const ValueFbm& f);

// Non-tiling smooth value noise in [0, 1] on the unit lattice: hashed corner values
// (hash_coords) blended trilinearly with smoothstep weights, in double. For modulation
// noise evaluated at world positions divided by a feature size (sim emitters).
double smooth_value_noise(uint32_t seed, double x, double y, double z);

} // namespace atlas::noise

#include "atlas/noise/value_noise.h"

#include <algorithm>

template <class Place>
void atlas::noise::value_fbm_row(std::span<float> out, const ValueFbm& f, std::span<const float> weights, Place&& place,
                                 std::vector<float>& scratch) {
    scratch.resize(out.size());
    std::fill(out.begin(), out.end(), 0.0f);
    for (int o = 0; o < f.octaves; ++o) {
        const FbmRow r = place(o);
        value_noise_row(scratch, r.x0, r.dx, r.y, r.z, r.period, f.seed + uint32_t(o) * f.seed_step, r.first);
        const float w = weights[size_t(o)];
        for (size_t i = 0; i < out.size(); ++i) out[i] += w * scratch[i];
    }
}

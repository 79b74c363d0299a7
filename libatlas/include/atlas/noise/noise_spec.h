// atlas/noise/noise_spec.h - what to generate: kernel, lattice, fractal, output.
//
// A NoiseSpec is a plain value describing one tileable noise signal. Graph
// nodes fill one from their parameters and hand it to fill_noise()
// (atlas/noise/fill.h). Every kernel is evaluated on an integer lattice that
// wraps with an integer `period` per axis, so the signal tiles exactly; the
// only randomness is atlas::hash_coords(seed, lattice point), so the result
// is the same for any thread count. docs/noise.md has every formula, range
// and the measured mean/variance bands.
//
// Validation: validate() throws atlas::Error naming the parameter
// ("noise: fractal.octaves = 0 is out of range [1, 16]").
#pragma once

#include "atlas/core/math.h"

#include <cstdint>
#include <string_view>

namespace atlas::noise {

enum class Kernel {
    Gradient,       // Perlin gradient noise, signed [-1, 1]
    Value,          // value noise (lattice values in [0, 1)), [0, 1]
    Worley,         // cellular distance (see WorleyFeature), [0, 1]
    PerlinWorley,   // Perlin FBM remapped with an inverted-Worley FBM as new minimum, [0, 1]
    Alligator,      // sparse-convolution billows: max1 - max2 of weighted bumps, [0, 1]
    CurlyAlligator, // 1 - Alligator, looked up at p + strength * curl(p), [0, 1]
    Curl,           // divergence-free vector noise: 3 channels in 3D, 2 in 2D
};

enum class WorleyFeature {
    F1,         // distance to the nearest feature point
    F2,         // distance to the second nearest
    F2MinusF1,  // F2 - F1: cell borders
    InvertedF1, // 1 - F1: billows
};

enum class WorleyMetric { Euclidean, Manhattan, Chebyshev };

// How octaves are combined. s_k is octave k mapped to [-1, 1] from the
// kernel's native range, v_k the octave in its native range, a_k = gain^k,
// and every sum is divided by sum(a_k), so outputs stay in a fixed range:
//   Fbm        sum a_k v_k         native range of the kernel
//   Turbulence sum a_k |s_k|       [0, 1]
//   Billow     sum a_k (2|s_k|-1)  [-1, 1]
//   Ridged     sum a_k (1-|s_k|)^2 [0, 1]
enum class Combinator { Fbm, Turbulence, Billow, Ridged };

// Octave k samples the kernel at lacunarity^k times the base coordinate on a
// lattice of period * lacunarity^k cells. Lacunarity is an integer so that
// every octave's period stays an integer and the sum still tiles.
struct FractalParams {
    int octaves = 1;       // [1, 16]
    int lacunarity = 2;    // [1, 1024]; period * lacunarity^(octaves-1) must stay <= 2^30 cells
    double gain = 0.5;     // amplitude ratio between octaves, [0, 4]
    Combinator combinator = Combinator::Fbm;
    void validate() const;
};

struct WorleyParams {
    WorleyFeature feature = WorleyFeature::InvertedF1;
    WorleyMetric metric = WorleyMetric::Euclidean;
    double jitter = 1.0; // feature point spread inside its cell, [0, 1] (0 = cell centres)
    void validate() const;
};

// The inverted-Worley FBM used as the new minimum of the Perlin part.
struct PerlinWorleyParams {
    int worley_octaves = 3;         // [1, 8], lacunarity 2, gain 0.5
    int worley_frequency_ratio = 1; // Worley base period = period * ratio, [1, 64]
    void validate() const;
};

// Alligator bumps: one feature point per cell with a random magnitude m in
// [0, 1) and the compact falloff m * (1 - (d/radius)^2)^3.
struct AlligatorParams {
    double radius = 1.0; // falloff radius in cells, [0.25, 1] (larger would need more neighbours)
    void validate() const;
};

// Curl noise: the curl of a potential of decorrelated gradient noises
// (3D: three, 2D: one, rotated gradient). Components are in units of
// potential per lattice cell; |component| <= 21 is guaranteed, the measured
// standard deviation is in docs/noise.md.
struct CurlParams {
    void validate() const {}
};

// Curly-Alligator: the Alligator lookup point is moved by
// strength * curl(p * frequency_ratio) before the lookup.
struct CurlyAlligatorParams {
    double curl_strength = 0.25;   // displacement in base cells per unit of curl, [0, 16]
    int curl_frequency_ratio = 1;  // curl period = period * ratio, [1, 64]
    void validate() const;
};

// Output stage, applied in this order after the fractal:
//   1. invert      v -> lo + hi - v over the signal's range
//   2. fold_count  twice-folded trick (Nubis³): t in [0, 1] -> |2t - 1|,
//                  repeated fold_count times (t is v mapped from its range)
//   3. remap       v -> out_min + (v - in_min) / (in_max - in_min) * (out_max - out_min),
//                  clamped to [out_min, out_max] when clamp is set
//   4. normalize   stretch the filled channel's measured min..max to
//                  out_min..out_max (fill_noise only; "use the full 0..1 range")
struct OutputParams {
    bool invert = false;
    int fold_count = 0; // [0, 8]
    bool remap = false;
    double in_min = 0, in_max = 1, out_min = 0, out_max = 1;
    bool clamp = true;
    bool normalize = false;
    void validate() const;
};

struct NoiseSpec {
    Kernel kernel = Kernel::Gradient;
    // Lattice cells per tile on each axis (2D uses x, y), [1, 2^30].
    Vec3i period{{4, 4, 4}};
    // Tiles across the field per axis: lattice coordinate of a field
    // position p in [0,1) is offset + frequency * p * period. An integer
    // keeps the field seamless; 0 gives a constant field. [0, 1e6].
    double frequency = 1.0;
    Vec3d offset{}; // in lattice cells; any finite value
    uint32_t seed = 0;
    FractalParams fractal;
    WorleyParams worley;
    PerlinWorleyParams perlin_worley;
    AlligatorParams alligator;
    CurlParams curl;
    CurlyAlligatorParams curly;
    OutputParams output;

    // Throws atlas::Error naming the first invalid parameter and its range.
    // dims is 2 or 3 (2D specs ignore period[2] and offset[2]).
    void validate(int dims = 3) const;
};

// Number of channels the kernel writes: 3 (3D) or 2 (2D) for Curl, else 1.
int noise_components(Kernel kernel, int dims);

// Range the kernel + fractal + output stage guarantee before `normalize`
// (for Curl: per component). Used by the tests and by callers that quantise.
struct ValueRange {
    double lo = 0, hi = 1;
};
ValueRange noise_output_range(const NoiseSpec& spec, int dims);

// Names used in graph files and error messages ("gradient", "f2-f1", ...).
std::string_view kernel_name(Kernel k);
Kernel parse_kernel(std::string_view name);             // throws atlas::Error
WorleyFeature parse_worley_feature(std::string_view name); // "f1", "f2", "f2-f1", "inverted-f1"
WorleyMetric parse_worley_metric(std::string_view name);   // "euclidean", "manhattan", "chebyshev"
Combinator parse_combinator(std::string_view name);       // "fbm", "turbulence", "billow", "ridged"

} // namespace atlas::noise

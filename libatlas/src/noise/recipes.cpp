#include "atlas/noise/recipes.h"

#include "atlas/core/error.h"
#include "atlas/noise/fill.h"

#include <string>

namespace atlas::noise {
namespace {

void check_size(const char* name, int s) {
    if (s < 1 || s > 1024) throw Error(std::string("noise: ") + name + " = " + std::to_string(s) + " is out of range [1, 1024]");
}

NoiseSpec base(Kernel k, int period, uint32_t seed, int octaves) {
    NoiseSpec s;
    s.kernel = k;
    s.period = {{period, period, period}};
    s.seed = seed;
    s.fractal.octaves = octaves;
    s.fractal.lacunarity = 2;
    s.fractal.gain = 0.5;
    return s;
}

NoiseSpec worley_fbm(int period, uint32_t seed) {
    NoiseSpec s = base(Kernel::Worley, period, seed, 3);
    s.worley.feature = WorleyFeature::InvertedF1;
    return s;
}

} // namespace

std::array<NoiseSpec, 4> nubis_noise_specs(uint32_t seed) {
    // Low frequency: 4 cells per tile; high: 8. Two octaves each keep the
    // billows' lacunarity cloud-like without washing the shapes out.
    std::array<NoiseSpec, 4> s = {base(Kernel::CurlyAlligator, 4, seed, 2), base(Kernel::CurlyAlligator, 8, seed + 1, 2),
                                  base(Kernel::Alligator, 4, seed + 2, 2), base(Kernel::Alligator, 8, seed + 3, 2)};
    for (auto& x : s) {
        x.curly.curl_strength = 0.35;
        x.curly.curl_frequency_ratio = 1;
        x.output.normalize = true; // use the full 0..1 range
    }
    return s;
}

Field3D make_nubis_noise(int size, uint32_t seed, const ProgressSink* progress, const MemoryBudget* budget) {
    check_size("size", size);
    Field3D f({{size, size, size}}, 4, Box3d{{{0, 0, 0}}, {{1, 1, 1}}}, {"r", "g", "b", "a"}, budget);
    const auto specs = nubis_noise_specs(seed);
    for (int c = 0; c < 4; ++c) fill_noise(f, c, specs[size_t(c)], progress);
    return f;
}

std::array<NoiseSpec, 4> hzd_low_specs(uint32_t seed) {
    NoiseSpec pw = base(Kernel::PerlinWorley, 4, seed, 3);
    pw.perlin_worley.worley_octaves = 3;
    pw.perlin_worley.worley_frequency_ratio = 1;
    return {pw, worley_fbm(4, seed + 1), worley_fbm(8, seed + 2), worley_fbm(16, seed + 3)};
}

std::array<NoiseSpec, 3> hzd_high_specs(uint32_t seed) { return {worley_fbm(8, seed + 4), worley_fbm(16, seed + 5), worley_fbm(32, seed + 6)}; }

NoiseSpec hzd_curl_spec(uint32_t seed) {
    NoiseSpec s = base(Kernel::Curl, 4, seed + 7, 1);
    // 2D curl components stay within [-10.5, 10.5]; in practice |c| < 4.
    s.output.remap = true;
    s.output.in_min = -4;
    s.output.in_max = 4;
    return s;
}

HzdNoise make_hzd_noise(int low_size, int high_size, int curl_size, uint32_t seed, const ProgressSink* progress,
                        const MemoryBudget* budget) {
    check_size("low_size", low_size);
    check_size("high_size", high_size);
    check_size("curl_size", curl_size);
    const Box3d unit{{{0, 0, 0}}, {{1, 1, 1}}};
    HzdNoise r{Field3D({{low_size, low_size, low_size}}, 4, unit, {"r", "g", "b", "a"}, budget),
               Field3D({{high_size, high_size, high_size}}, 3, unit, {"r", "g", "b"}, budget),
               Field2D({{curl_size, curl_size}}, 2, Box2d{{{0, 0}}, {{1, 1}}}, {"r", "g"}, budget)};
    const auto low = hzd_low_specs(seed);
    for (int c = 0; c < 4; ++c) fill_noise(r.low, c, low[size_t(c)], progress);
    const auto high = hzd_high_specs(seed);
    for (int c = 0; c < 3; ++c) fill_noise(r.high, c, high[size_t(c)], progress);
    fill_noise(r.curl, 0, hzd_curl_spec(seed), progress);
    return r;
}

} // namespace atlas::noise

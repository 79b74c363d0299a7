// Shared helpers for the compress tests: deterministic random and adversarial blocks.
#pragma once

#include <algorithm>
#include <array>

#include <cmath>
#include <cstdint>
#include <vector>

namespace atlas::compress::test {

#ifdef NDEBUG
constexpr int kRandomBlocks = 100000; // >= 10^5 per format in Release
constexpr int kExhaustiveDivisor = 1;
#else
constexpr int kRandomBlocks = 5000; // Debug / sanitizer builds
constexpr int kExhaustiveDivisor = 20; // exhaustive BC4 searches are ~20x slower there
#endif

// Uniform [0,1) from a 64-bit counter (splitmix64), independent of thread or order.
inline double unit(uint64_t seed, uint64_t i) {
    uint64_t z = seed * 0x9E3779B97F4A7C15ull + i * 0xBF58476D1CE4E5B9ull + 0x94D049BB133111EBull;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    z ^= z >> 31;
    return double(z >> 11) * (1.0 / 9007199254740992.0);
}

// A flat RGB block: 16 texels of one colour (the encoders' flat-block memos).
inline std::array<float, 48> flat_rgb_block(float r, float g, float b) {
    std::array<float, 48> a;
    for (size_t t = 0; t < 16; ++t) {
        a[3 * t] = r;
        a[3 * t + 1] = g;
        a[3 * t + 2] = b;
    }
    return a;
}

// Block `k` of a mixed stream: noise, gradients, two-level, steps, constants, extremes.
inline void scalar_block(uint64_t k, float lo, float hi, float out[16]) {
    const int kind = int(k % 7);
    const double a = unit(k, 1), b = unit(k, 2), c = unit(k, 3);
    for (int t = 0; t < 16; ++t) {
        const int x = t % 4, y = t / 4;
        double v = 0;
        switch (kind) {
        case 0: v = unit(k, 10 + t); break;                                  // noise
        case 1: v = a + (b - 0.5) * 0.2 * x + (c - 0.5) * 0.2 * y; break;    // smooth gradient
        case 2: v = (unit(k, 10 + t) < 0.5) ? a : b; break;                  // two-level
        case 3: v = x < 2 ? 0.0 : 1.0; break;                                // full-range step
        case 4: v = a; break;                                                // constant
        case 5: v = (t % 2) ? 1.0 : 0.0; break;                              // extremes
        default: v = a + 0.01 * unit(k, 10 + t); break;                      // narrow noise
        }
        v = std::clamp(v, 0.0, 1.0);
        out[t] = float(lo + (hi - lo) * v);
    }
}

} // namespace atlas::compress::test

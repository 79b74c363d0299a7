// Internal: IEEE half-precision conversion (round to nearest even, and round down).
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>

namespace atlas::compress::detail {

inline float half_to_float(uint16_t h) {
    const uint32_t s = uint32_t(h & 0x8000) << 16;
    const int e = (h >> 10) & 31;
    const uint32_t m = h & 1023;
    if (e == 0) {
        float f = std::ldexp(float(m), -24);
        return s ? -f : f;
    }
    uint32_t bits = e == 31 ? (s | 0x7f800000u | (m << 13)) : (s | (uint32_t(e + 112) << 23) | (m << 13));
    float f;
    std::memcpy(&f, &bits, 4);
    return f;
}

inline uint16_t float_to_half(float f) {
    uint32_t x;
    std::memcpy(&x, &f, 4);
    const uint16_t sign = uint16_t((x >> 16) & 0x8000);
    x &= 0x7fffffffu;
    if (x >= 0x7f800000u) return uint16_t(sign | 0x7c00 | (x > 0x7f800000u ? 0x200 : 0));
    if (x >= 0x477ff000u) return uint16_t(sign | 0x7c00); // rounds to infinity
    if (x < 0x38800000u) { // below the smallest normal half: units of 2^-24
        float a;
        std::memcpy(&a, &x, 4);
        return uint16_t(sign | uint16_t(std::nearbyint(a * 16777216.0f)));
    }
    uint32_t h = (((x >> 23) - 112) << 10) | ((x & 0x7fffffu) >> 13);
    const uint32_t rem = x & 0x1fffu;
    if (rem > 0x1000u || (rem == 0x1000u && (h & 1))) ++h;
    return uint16_t(sign | h);
}

// The largest half <= f (f finite).
inline uint16_t float_to_half_down(float f) {
    uint16_t h = float_to_half(f);
    if (half_to_float(h) > f) {
        if (h & 0x8000) ++h;
        else if ((h & 0x7fff) == 0) h = 0x8001;
        else --h;
    }
    return h;
}

} // namespace atlas::compress::detail

// BC4 decoding: each decoder model's palette of a pair, the interval over a decoder set, and the block decoders.
#include "atlas/compress/bc4.h"

#include "bc4_internal.h"

#include <algorithm>
#include <cmath>

namespace atlas::compress {

namespace {

using namespace detail::bc4;

// Palette of a pair under one decoder; returns the entry count (always 8).
void palette_values(uint8_t b0, uint8_t b1, bool snorm, Decoder d, float v[8]) {
    const int e0 = level(b0, snorm), e1 = level(b1, snorm);
    const float scale = snorm ? 127.0f : 255.0f;
    const bool eight = snorm ? (static_cast<int8_t>(b0) > static_cast<int8_t>(b1)) : (b0 > b1);
    const bool integer = (d == Decoder::Tool8 || d == Decoder::Tool8Round);
    const bool round = d == Decoder::Tool8Round;
    v[0] = float(e0) / scale;
    v[1] = float(e1) / scale;
    const int steps = eight ? 7 : 5;
    const int count = eight ? 6 : 4;
    for (int k = 0; k < count; ++k) {
        const int num = (steps - 1 - k) * e0 + (k + 1) * e1;
        // Tool decoders truncate toward zero in integer arithmetic (squish, bcdec).
        // Rounding tools add half the divisor (toward zero for negative SNORM sums).
        const int rounded = round ? (num >= 0 ? (num + steps / 2) / steps : (num - steps / 2) / steps) : num / steps;
        v[2 + k] = integer ? float(rounded) / scale : float(num) / float(steps) / scale;
    }
    if (!eight) {
        v[6] = snorm ? -1.0f : 0.0f;
        v[7] = 1.0f;
    }
}

// The exact palette of a pair under one model, in double (num / (steps * scale) has a
// relative error of ~1e-16 there), for bounds that hold in exact arithmetic.
void palette_exact(uint8_t b0, uint8_t b1, bool snorm, Decoder d, double v[8]) {
    const int e0 = level(b0, snorm), e1 = level(b1, snorm);
    const double scale = snorm ? 127.0 : 255.0;
    const bool eight = snorm ? (static_cast<int8_t>(b0) > static_cast<int8_t>(b1)) : (b0 > b1);
    const bool integer = (d == Decoder::Tool8 || d == Decoder::Tool8Round);
    const bool round = d == Decoder::Tool8Round;
    v[0] = e0 / scale;
    v[1] = e1 / scale;
    const int steps = eight ? 7 : 5;
    const int count = eight ? 6 : 4;
    for (int k = 0; k < count; ++k) {
        const int num = (steps - 1 - k) * e0 + (k + 1) * e1;
        const int rounded = round ? (num >= 0 ? (num + steps / 2) / steps : (num - steps / 2) / steps) : num / steps;
        v[2 + k] = integer ? rounded / scale : num / (double(steps) * scale);
    }
    if (!eight) {
        v[6] = snorm ? -1.0 : 0.0;
        v[7] = 1.0;
    }
}

// The smallest float >= x (1 + 1e-15) and the largest <= x (1 - 1e-15) (for x >= 0;
// mirrored below 0): bounds of the exact value and of any double computation of it.
// Values a float holds exactly (0, +-1: the palettes' denominators are odd, so no
// other value is dyadic) are computed exactly in double too and stay as they are.
float float_up(double x) {
    if (double(float(x)) == x) return float(x);
    const double t = x + std::fabs(x) * 1e-15;
    float f = float(t);
    if (double(f) < t) f = std::nextafter(f, INFINITY);
    return f;
}
float float_down(double x) {
    if (double(float(x)) == x) return float(x);
    const double t = x - std::fabs(x) * 1e-15;
    float f = float(t);
    if (double(f) > t) f = std::nextafter(f, -INFINITY);
    return f;
}

} // namespace

namespace detail::bc4 {

void interval_palette(uint8_t b0, uint8_t b1, bool snorm, DecoderSet set, detail::Palette<1>& p, bool exact_bounds) {
    p.n = 8;
    float ref[8];
    palette_values(b0, b1, snorm, Decoder::Reference, ref);
    for (int i = 0; i < 8; ++i) { p.ref[i][0] = ref[i]; p.lo[i][0] = ref[i]; p.hi[i][0] = ref[i]; }
    bool any = false;
    for (int di = 0; di < kDecoderCount; ++di) {
        if (!(set & (DecoderSet(1) << di))) continue; // no allocation: 65,536 palettes per encoder
        const Decoder d = static_cast<Decoder>(di);
        float v[8];
        if (d == Decoder::Conformant) {
            const bool eight = snorm ? (static_cast<int8_t>(b0) > static_cast<int8_t>(b1)) : (b0 > b1);
            const int interp = eight ? 8 : 6; // endpoints and the constants are exact conversions
            for (int i = 0; i < 8; ++i) {
                float t = (i >= 2 && i < interp) ? kConformantTolerance : 0.0f;
                float lo = ref[i] - t, hi = ref[i] + t;
                if (!any) { p.lo[i][0] = lo; p.hi[i][0] = hi; }
                else { p.lo[i][0] = std::min(p.lo[i][0], lo); p.hi[i][0] = std::max(p.hi[i][0], hi); }
            }
            any = true;
            continue;
        }
        palette_values(b0, b1, snorm, d, v);
        for (int i = 0; i < 8; ++i) {
            if (!any) { p.lo[i][0] = v[i]; p.hi[i][0] = v[i]; }
            else { p.lo[i][0] = std::min(p.lo[i][0], v[i]); p.hi[i][0] = std::max(p.hi[i][0], v[i]); }
        }
        any = true;
    }
    if (exact_bounds)
        for (int di = 0; di < kDecoderCount; ++di) {
            if (!(set & (DecoderSet(1) << di))) continue;
            const Decoder d = static_cast<Decoder>(di);
            double x[8];
            palette_exact(b0, b1, snorm, d == Decoder::Conformant ? Decoder::Reference : d, x);
            const bool eight = snorm ? (static_cast<int8_t>(b0) > static_cast<int8_t>(b1)) : (b0 > b1);
            for (int i = 0; i < 8; ++i) {
                const double t = (d == Decoder::Conformant && i >= 2 && i < (eight ? 8 : 6)) ? 1.0 / 255.0 : 0.0;
                p.lo[i][0] = std::min(p.lo[i][0], float_down(x[i] - t));
                p.hi[i][0] = std::max(p.hi[i][0], float_up(x[i] + t));
            }
        }
}

} // namespace detail::bc4

void decode_bc4_block(const uint8_t block[8], bool snorm, Decoder d, float out[16]) {
    float v[8];
    palette_values(block[0], block[1], snorm, d == Decoder::Conformant ? Decoder::Reference : d, v);
    uint64_t bits = 0;
    for (int i = 0; i < 6; ++i) bits |= uint64_t(block[2 + i]) << (8 * i);
    for (int t = 0; t < 16; ++t) out[t] = v[(bits >> (3 * t)) & 7];
}

void decode_bc4_interval(const uint8_t block[8], bool snorm, DecoderSet set, float lo[16], float hi[16]) {
    detail::Palette<1> p;
    interval_palette(block[0], block[1], snorm, set, p);
    uint64_t bits = 0;
    for (int i = 0; i < 6; ++i) bits |= uint64_t(block[2 + i]) << (8 * i);
    for (int t = 0; t < 16; ++t) {
        int i = int((bits >> (3 * t)) & 7);
        lo[t] = p.lo[i][0];
        hi[t] = p.hi[i][0];
    }
}

} // namespace atlas::compress

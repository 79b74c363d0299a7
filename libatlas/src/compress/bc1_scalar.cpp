// bc1-scalar: weights from the decoder models, greedy round-down endpoints and a
// candidate search over the block's own values (Nubis: "adjust the high endpoint
// down to improve average error").
#include "atlas/compress/bc1_scalar.h"

#include "atlas/compress/bc1.h"
#include "atlas/core/error.h"
#include "bc1_palette.h"
#include "bc1_scalar_palette.h"

#include <algorithm>
#include <cmath>
#include <memory>

namespace atlas::compress {

namespace {

using detail::channel_level_value;

// Largest level index whose (weighted) value is <= v, or 0. Levels increase with
// the index, so the levels that fit form a prefix: binary search.
int floor_level(const float* table, int n, float w, float v) {
    int lo = 0, hi = n; // table[i] * w <= v for every i < lo; fails for i >= hi
    while (lo < hi) {
        const int mid = (lo + hi) / 2;
        if (table[mid] * w <= v) lo = mid + 1;
        else hi = mid;
    }
    return lo > 0 ? lo - 1 : 0;
}

// Greedy split of v into R, G, B; `nearest_last` rounds the B digit to nearest.
uint16_t split(float v, const ScalarUnpack& u, const float* t5, const float* t6, bool nearest_last) {
    const int r = floor_level(t5, 32, u.weights[0], v);
    float rest = v - t5[r] * u.weights[0];
    const int g = floor_level(t6, 64, u.weights[1], rest);
    rest -= t6[g] * u.weights[1];
    int b = floor_level(t5, 32, u.weights[2], rest);
    if (nearest_last && b < 31 && std::fabs(t5[b + 1] * u.weights[2] - rest) < std::fabs(t5[b] * u.weights[2] - rest)) ++b;
    return uint16_t((r << 11) | (g << 5) | b);
}

// A small sorted set of endpoint codes without allocation.
struct Codes {
    uint16_t v[64];
    int n = 0;
    void add(uint16_t c) { if (n < 64) v[n++] = c; }
    void sort_unique() {
        std::sort(v, v + n);
        n = int(std::unique(v, v + n) - v);
    }
};

} // namespace

ScalarUnpack bc1_scalar_unpack(DecoderSet decoders) {
    if (decoders == 0) decoders = kReferenceOnly;
    ScalarUnpack u;
    u.decoders = decoders;
    float step5 = 0, step6 = 0;
    for (Decoder d : decoders_in(decoders)) {
        for (int i = 0; i < 31; ++i) step5 = std::max(step5, channel_level_value(i + 1, 5, d) - channel_level_value(i, 5, d));
        for (int i = 0; i < 63; ++i) step6 = std::max(step6, channel_level_value(i + 1, 6, d) - channel_level_value(i, 6, d));
    }
    u.weights = {1.0f, step5, step5 * step6};
    u.max_value = u.weights[0] + u.weights[1] + u.weights[2];
    u.endpoint_step = u.weights[2] * step5;
    return u;
}

void decode_bc1_scalar_block(const uint8_t block[8], Decoder d, const ScalarUnpack& u, float out[16]) {
    float rgb[48];
    decode_bc1_block(block, d, rgb);
    for (int t = 0; t < 16; ++t)
        out[t] = rgb[3 * t] * u.weights[0] + rgb[3 * t + 1] * u.weights[1] + rgb[3 * t + 2] * u.weights[2];
}

BlockResult encode_bc1_scalar_block(const float src[16], const ScalarUnpack& u, const BlockOptions& options,
                                    uint8_t out[8]) {
    if (options.decoders != u.decoders && !(options.decoders == 0 && u.decoders == kReferenceOnly))
        throw Error("encode_bc1_scalar_block: options.decoders differs from the unpack weights' decoder set");
    // Round-down against the largest decoded level keeps endpoints below the source
    // for every decoder; the reference table gives the nearest alternatives.
    std::unique_ptr<detail::ScalarTables> local;
    const detail::ScalarTables& T = detail::scalar_tables(u, local);
    float smin = src[0], smax = src[0];
    for (int t = 1; t < 16; ++t) { smin = std::min(smin, src[t]); smax = std::max(smax, src[t]); }
    // Margins below the source: 0, and for the Conformant model its endpoint
    // tolerance (base, then base + the bound of its relative term).
    float margins[3] = {0, 0, 0};
    int nm = 1;
    if (u.decoders & decoder_bit(Decoder::Conformant)) {
        const float base = kBc1ConformantBase * u.max_value * 1.0001f;
        const float rel = kConformantRelative * (u.weights[0] * (smax - smin + 2.0f / 31.0f) + u.weights[1] + u.weights[2]);
        margins[nm++] = base;
        margins[nm++] = base + rel;
    }
    float sorted[16];
    std::copy(src, src + 16, sorted);
    std::sort(sorted, sorted + 16);
    Codes lows, highs;
    // One-sided under Conformant: endpoints without margin are never feasible.
    for (int k = (nm > 1 && options.one_sided_below) ? 1 : 0; k < nm; ++k) {
        const float m = margins[k];
        lows.add(split(smin - m, u, T.hi5, T.hi6, false));
        highs.add(split(smax - m, u, T.hi5, T.hi6, false));
        if (options.quality != Quality::Fast) { // Nubis: move the high endpoint down
            highs.add(split(sorted[13] - m, u, T.hi5, T.hi6, false));
            highs.add(split(sorted[10] - m, u, T.hi5, T.hi6, false));
        }
        if (options.quality == Quality::Best)
            for (int t = 0; t < 16; ++t) highs.add(split(src[t] - m, u, T.hi5, T.hi6, false));
    }
    if (!options.one_sided_below) {
        lows.add(split(smin, u, T.ref5, T.ref6, true));
        highs.add(split(smax, u, T.ref5, T.ref6, true));
    }
    highs.sort_unique();
    lows.sort_unique();

    detail::Selection best;
    uint16_t b0 = 0, b1 = 0;
    bool have = false;
    auto consider = [&](uint16_t c0, uint16_t c1) {
        detail::Palette<1> p;
        detail::scalar_interval_palette(T, c0, c1, p);
        detail::Selection s = detail::select_indices(p, src, options.one_sided_below, have ? best.max_err : INFINITY);
        if (!std::isfinite(s.max_err)) return;
        if (!have || detail::better(s, best)) { best = s; b0 = c0; b1 = c1; have = true; }
    };
    auto both = [&](uint16_t a, uint16_t b) {
        consider(std::max(a, b), std::min(a, b));
        consider(std::min(a, b), std::max(a, b));
    };
    for (int i = 0; i < highs.n; ++i)
        for (int j = 0; j < lows.n; ++j) both(highs.v[i], lows.v[j]);
    const bool missed = !have || (options.max_error >= 0 && best.max_err > options.max_error);
    if (options.quality == Quality::Best || missed) {
        // Nudge both endpoint codes by a few units (neighbouring codes are neighbouring values).
        for (int round = 0; round < 4 && have; ++round) {
            const uint16_t k0 = b0, k1 = b1;
            for (int d0 = -3; d0 <= 3; ++d0)
                for (int d1 = -3; d1 <= 3; ++d1) {
                    const int a = int(k0) + d0, b = int(k1) + d1;
                    if (a < 0 || b < 0 || a > 65535 || b > 65535) continue;
                    both(uint16_t(a), uint16_t(b));
                }
            if (k0 == b0 && k1 == b1) break;
        }
    }
    if (!have) { // unreachable for sources >= 0: (0,0) gives the exact black entry
        both(0, 0);
        if (!have) {
            detail::Palette<1> p;
            detail::scalar_interval_palette(T, 0, 0, p);
            detail::Selection s = detail::select_indices(p, src, false);
            detail::write_bc1_block(0, 0, s.idx, out);
            return {s.max_err, s.sum_sq, false};
        }
    }
    detail::write_bc1_block(b0, b1, best.idx, out);
    return {best.max_err, best.sum_sq, true};
}

} // namespace atlas::compress

// BC4 decoding under each decoder model, and the endpoint search.
#include "atlas/compress/bc4.h"

#include "palette_search.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

namespace atlas::compress {

namespace {

// Endpoint byte -> integer level (-127..127 for SNORM, -128 reads as -127).
int level(uint8_t b, bool snorm) {
    if (!snorm) return b;
    int v = static_cast<int8_t>(b);
    return v < -127 ? -127 : v;
}

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

void interval_palette(uint8_t b0, uint8_t b1, bool snorm, DecoderSet set, detail::Palette<1>& p) {
    p.n = 8;
    float ref[8];
    palette_values(b0, b1, snorm, Decoder::Reference, ref);
    for (int i = 0; i < 8; ++i) { p.ref[i][0] = ref[i]; p.lo[i][0] = ref[i]; p.hi[i][0] = ref[i]; }
    bool any = false;
    for (Decoder d : decoders_in(set)) {
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
}

void write_block(uint8_t b0, uint8_t b1, const uint8_t idx[16], uint8_t out[8]) {
    out[0] = b0;
    out[1] = b1;
    uint64_t bits = 0;
    for (int t = 0; t < 16; ++t) bits |= uint64_t(idx[t] & 7) << (3 * t);
    for (int i = 0; i < 6; ++i) out[2 + i] = uint8_t(bits >> (8 * i));
}

} // namespace

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

struct Bc4Encoder::Tables {
    std::vector<detail::Palette<1>> pal; // index b0 * 256 + b1
    std::vector<float> pal_min, pal_max; // range of lo / hi over the entries (pruning)
};

Bc4Encoder::Bc4Encoder(bool snorm, const BlockOptions& options)
    : snorm_(snorm), options_(options), tables_(std::make_unique<Tables>()) {
    if (options_.decoders == 0) options_.decoders = kReferenceOnly;
    tables_->pal.resize(65536);
    tables_->pal_min.resize(65536);
    tables_->pal_max.resize(65536);
    for (int k = 0; k < 65536; ++k) {
        auto& p = tables_->pal[size_t(k)];
        interval_palette(uint8_t(k >> 8), uint8_t(k & 255), snorm_, options_.decoders, p);
        float mn = p.lo[0][0], mx = p.hi[0][0];
        for (int i = 1; i < 8; ++i) { mn = std::min(mn, p.lo[i][0]); mx = std::max(mx, p.hi[i][0]); }
        tables_->pal_min[size_t(k)] = mn;
        tables_->pal_max[size_t(k)] = mx;
    }
}

Bc4Encoder::~Bc4Encoder() = default;

BlockResult Bc4Encoder::encode_exhaustive(const float src[16], uint8_t out[8]) const {
    float smin = src[0], smax = src[0];
    for (int t = 1; t < 16; ++t) { smin = std::min(smin, src[t]); smax = std::max(smax, src[t]); }
    detail::Selection best;
    int best_k = -1;
    const bool os = options_.one_sided_below;
    for (int k = 0; k < 65536; ++k) {
        // Lower bound: the block's extremes must be reached by the palette's range.
        float lb = std::max(tables_->pal_min[size_t(k)] - smin, smax - tables_->pal_max[size_t(k)]);
        if (lb > best.max_err) continue;
        if (os && tables_->pal_min[size_t(k)] > smin) continue;
        detail::Selection s = detail::select_indices(tables_->pal[size_t(k)], src, os, best.max_err);
        if (best_k < 0 ? std::isfinite(s.max_err) : detail::better(s, best)) { best = s; best_k = k; }
    }
    if (best_k < 0) { // cannot happen for UNORM/SNORM (0 / -1 entry), kept for safety
        std::memset(out, 0, 8);
        return {std::numeric_limits<float>::infinity(), 0, false};
    }
    write_block(uint8_t(best_k >> 8), uint8_t(best_k & 255), best.idx, out);
    return {best.max_err, best.sum_sq, true};
}

BlockResult Bc4Encoder::encode(const float src[16], uint8_t out[8]) const {
    if (options_.quality == Quality::Best) return encode_exhaustive(src, out);
    float smin = src[0], smax = src[0];
    for (int t = 1; t < 16; ++t) { smin = std::min(smin, src[t]); smax = std::max(smax, src[t]); }
    const float scale = snorm_ ? 127.0f : 255.0f;
    const int lo_lim = snorm_ ? -127 : 0, hi_lim = snorm_ ? 127 : 255;
    const int radius = 0; // floor / ceil of the extremes; misses fall back to the exhaustive search
    auto clampi = [&](int v) { return std::clamp(v, lo_lim, hi_lim); };
    const int qlo0 = clampi(int(std::floor(smin * scale))), qlo1 = clampi(int(std::ceil(smin * scale)));
    const int qhi0 = clampi(int(std::floor(smax * scale))), qhi1 = clampi(int(std::ceil(smax * scale)));
    auto byte_of = [&](int v) { return uint8_t(snorm_ ? uint8_t(int8_t(v)) : uint8_t(v)); };
    detail::Selection best;
    int best_k = -1;
    const bool os = options_.one_sided_below;
    auto consider = [&](int a, int b) {
        int k = int(byte_of(a)) * 256 + int(byte_of(b));
        detail::Selection s = detail::select_indices(tables_->pal[size_t(k)], src, os, best.max_err);
        if (best_k < 0 ? std::isfinite(s.max_err) : detail::better(s, best)) { best = s; best_k = k; }
    };
    const int hstep = options_.quality == Quality::Fast ? std::max(1, qhi1 - qhi0) : 1;
    for (int h = qhi0 - radius; h <= qhi1 + radius; h += hstep)
        for (int l = qlo0 - radius; l <= qlo1 + radius; ++l) {
            int a = clampi(h), b = clampi(l);
            if (a > b) consider(a, b);  // 8 interpolated values
            if (options_.quality != Quality::Fast || options_.one_sided_below)
                consider(std::min(a, b), std::max(a, b)); // 6 values plus exact extremes
        }
    const bool missed = best_k < 0 || (options_.max_error >= 0 && best.max_err > options_.max_error);
    if (missed) return encode_exhaustive(src, out);
    write_block(uint8_t(best_k >> 8), uint8_t(best_k & 255), best.idx, out);
    return {best.max_err, best.sum_sq, true};
}

} // namespace atlas::compress

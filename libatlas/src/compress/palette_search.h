// Internal: choosing the 16 indices of a block for a palette of intervals.
//
// A decoder set turns each palette entry into an interval [lo, hi] per channel that
// contains the entry's decoded value under every decoder of the set, and is tight
// (lo and hi are reached). So max over decoders |dec - s| = max(hi - s, s - lo) and
// "every decoder <= s" is exactly hi <= s: the guarantees reduce to interval tests.
#pragma once

#include <algorithm>
#include <cstdint>
#include <limits>

namespace atlas::compress::detail {

template <int C>
struct Palette {
    int n = 0;
    float lo[8][C];
    float hi[8][C];
    float ref[8][C]; // Reference decoder value (for the squared-error tie break)
};

struct Selection {
    float max_err = std::numeric_limits<float>::infinity();
    double sum_sq = 0;
    uint8_t idx[16] = {};
};

// Lexicographic objective: max error first, then squared reference error.
inline bool better(const Selection& a, const Selection& b) {
    return a.max_err < b.max_err || (a.max_err == b.max_err && a.sum_sq < b.sum_sq);
}

// Per-texel worst-case error of entry i; +inf when one-sided and above the source.
template <int C, bool OneSided>
inline float entry_error_t(const Palette<C>& p, int i, const float* s) {
    float e = 0;
    for (int c = 0; c < C; ++c) {
        if constexpr (OneSided)
            if (p.hi[i][c] > s[c]) return std::numeric_limits<float>::infinity();
        const float a = p.hi[i][c] - s[c], b = s[c] - p.lo[i][c];
        e = std::max(e, a > b ? a : b);
    }
    return e;
}

template <int C, bool OneSided>
inline Selection select_indices_t(const Palette<C>& p, const float* src, float stop_above) {
    Selection out;
    float block_max = 0;
    for (int t = 0; t < 16; ++t) {
        float best = std::numeric_limits<float>::infinity();
        for (int i = 0; i < p.n; ++i) best = std::min(best, entry_error_t<C, OneSided>(p, i, src + t * C));
        if (!(best <= stop_above)) return out; // infeasible or worse than the incumbent
        block_max = std::max(block_max, best);
    }
    out.max_err = block_max;
    double total = 0;
    for (int t = 0; t < 16; ++t) {
        const float* s = src + t * C;
        double best_sq = std::numeric_limits<double>::infinity();
        int best_i = 0;
        for (int i = 0; i < p.n; ++i) {
            if (!(entry_error_t<C, OneSided>(p, i, s) <= block_max)) continue;
            double sq = 0;
            for (int c = 0; c < C; ++c) { const double d = double(p.ref[i][c]) - s[c]; sq += d * d; }
            if (sq < best_sq) { best_sq = sq; best_i = i; }
        }
        out.idx[t] = uint8_t(best_i);
        total += best_sq;
    }
    out.sum_sq = total;
    return out;
}

// Optimal indices for a fixed palette: minimises the block's max error, then the
// squared Reference error among index choices that keep that max. Returns
// max_err = +inf early when the max already exceeds `stop_above`.
template <int C>
inline Selection select_indices(const Palette<C>& p, const float* src, bool one_sided,
                                float stop_above = std::numeric_limits<float>::infinity()) {
    return one_sided ? select_indices_t<C, true>(p, src, stop_above) : select_indices_t<C, false>(p, src, stop_above);
}

} // namespace atlas::compress::detail

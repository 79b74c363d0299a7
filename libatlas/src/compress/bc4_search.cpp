// BC4 endpoint search: fast / normal's candidate pairs, the exhaustive search, and Bc4Encoder::encode / encode_blocks.
#include "atlas/compress/bc4.h"

#include "bc4_internal.h"
#include "bc4_test_hooks.h"
#include "palette_search.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <vector>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace atlas::compress {

namespace {

using namespace detail::bc4;

// The exhaustive search over all 65,536 pairs, starting from an incumbent (`best` and
// its pair `best_k`; best_k < 0: none). Returns the best pair's index (-1: none). Returns the lexicographic minimum of (max error, squared error, pair
// index) over the feasible pairs, exactly what a plain scan in index order keeping
// strict improvements returns: pairs are skipped only by true lower bounds.
//   * A pair's entries other than the constants span [imin, imax]; every texel that
//     the constants cannot serve within the incumbent's error E must be within E of
//     that span (float subtraction is monotone, so this bounds the computed error).
//   * For the 8-value mode every texel counts; rows are skipped by their extremes.
int search_all_pairs(const PairTables& T, const float src[16], bool os, detail::Selection& best, int best_k) {
    // An exact incumbent (max error 0, squared error 0: constant blocks on a level or a
    // constant, e.g. an SDF clamped at its range) can only tie: the answer is the lowest
    // index with an exact palette, found by a scan in index order (every 6-value pair
    // serves a block at 0 or 1 exactly, and none of them is pruned by the bounds below).
    if (best_k >= 0 && best.max_err == 0.0f && best.sum_sq == 0.0) {
        for (int k = 0; k < best_k; ++k) {
            const detail::Selection s = detail::select_indices(T.pal[size_t(k)], src, os, 0.0f);
            if (s.max_err == 0.0f && s.sum_sq == 0.0) { best = s; return k; }
        }
        return best_k;
    }
    float smin = src[0], smax = src[0];
    for (int t = 1; t < 16; ++t) { smin = std::min(smin, src[t]); smax = std::max(smax, src[t]); }
    // Error of a constant entry c for texel s, as select_indices computes it.
    auto const_err = [&](float c, float s) {
        if (os && c > s) return INFINITY;
        const float a = c - s, b = s - c;
        return std::max(0.0f, a > b ? a : b);
    };
    // The sorted texels, median and quartiles first: a palette with a gap inside the
    // block's range is usually rejected by one of the first texels tried.
    float sorted[16], probe[16];
    std::copy(src, src + 16, sorted);
    std::sort(sorted, sorted + 16);
    // Spacing bound. A texel s is served within E only by an entry whose exact grid
    // value x_j (TablesT::slack) is within E' = E + slack of it, so the texels lie in
    // the union of [x_j - E', x_j + E']. If the block's texels span more than 2E', two
    // grid neighbours serve its extremes and every window between them lies inside the
    // texels' range; a window of length step - 2E' > G (the largest gap between sorted
    // texels) would contain a texel that nothing serves. Hence step <= 2E' + G: pairs
    // (and whole rows) whose endpoint spread exceeds steps * (2E' + G) have an error
    // above E, strictly, and are skipped. The 6-value mode applies this to the texels
    // its constants cannot serve (the mid set).
    double gap = 0;
    for (int t = 0; t + 1 < 16; ++t) gap = std::max(gap, double(sorted[t + 1]) - double(sorted[t]));
    float lim8 = INFINITY, lim6 = INFINITY; // spread limits of the two modes for the incumbent's E
    float row8_hi = INFINITY, row6_lo = -INFINITY; // e0 bounds of the rows
    auto spread_limit = [](double e, double slack, double g, int steps, double span) {
        // + 4e-7: values are in [-1, 1], where that is a few float ulps, so an error
        // rounded down to E in float is not skipped either.
        const double ep = e + slack + 4e-7;
        if (!(span > 2 * ep)) return INFINITY; // one entry may serve every texel
        const double lim = double(steps) * (2 * ep + g);
        return float(lim * (1 + 1e-6) + 1e-6); // rounded outward: a looser bound is still a bound
    };
    float mid_lo = INFINITY, mid_hi = -INFINITY, mid_for = -1;
    auto update_mid = [&]() { // texels the 6-value mode's constants cannot serve within E
        if (mid_for == best.max_err) return;
        mid_for = best.max_err;
        mid_lo = INFINITY;
        mid_hi = -INFINITY;
        double mid_gap = 0, prev = NAN;
        for (int t = 0; t < 16; ++t) {
            const float v = sorted[t];
            if (!(const_err(T.c_lo, v) <= best.max_err) && !(const_err(T.c_hi, v) <= best.max_err)) {
                mid_lo = std::min(mid_lo, v);
                mid_hi = std::max(mid_hi, v);
                if (!std::isnan(prev)) mid_gap = std::max(mid_gap, double(v) - prev);
                prev = v;
            }
        }
        const double e = best.max_err;
        lim8 = std::isfinite(best.max_err) ? spread_limit(e, T.slack[0], gap, 7, double(smax) - double(smin)) : INFINITY;
        lim6 = std::isfinite(best.max_err) && mid_lo <= mid_hi ? spread_limit(e, T.slack[1], mid_gap, 5, double(mid_hi) - double(mid_lo))
                                                               : INFINITY;
        // 8-value rows: the lowest entry (e1) serves smin, so e0 <= smin + E' + lim8.
        row8_hi = std::isfinite(lim8) ? float(double(smin) + e + T.slack[0] + double(lim8) + 1e-6) : INFINITY;
        // 6-value rows: the highest interpolated entry (e1 <= e0 + lim6) serves mid_hi.
        row6_lo = std::isfinite(lim6) ? float(double(mid_hi) - e - T.slack[1] - double(lim6) - 1e-6) : -INFINITY;
    };
    auto bound = [](float imn, float imx, float lo, float hi) { return lo > hi ? -INFINITY : std::max(imn - lo, hi - imx); };
    constexpr int kProbeOrder[16] = {7, 3, 11, 1, 5, 9, 13, 0, 2, 4, 6, 8, 10, 12, 14, 15};
    for (int t = 0; t < 16; ++t) probe[t] = sorted[kProbeOrder[t]];
    uint8_t cand[256];
    // Rows outward from the incumbent's row: good pairs (a small E, strong bounds) come
    // early. The order does not change the result (the minimum with index tie-break).
    const int start = best_k >= 0 ? best_k >> 8 : 0;
    for (int step = 0; step < 512; ++step) {
        const int b0 = start + ((step & 1) ? (step + 1) / 2 : -(step / 2));
        if (b0 < 0 || b0 > 255) continue;
        update_mid();
        const bool row8 = !(bound(T.row_imin[b0][0], T.row_imax[b0][0], smin, smax) > best.max_err) && !(T.val[b0] > row8_hi);
        const bool row6 = !(bound(T.row_imin[b0][1], T.row_imax[b0][1], mid_lo, mid_hi) > best.max_err) && !(T.val[b0] < row6_lo);
        if (!row8 && !row6) continue;
        // Pairs of the row that pass the range bounds (the incumbent may improve
        // below, so this is a superset; select_indices has the final word).
        int n = 0;
        const size_t row = size_t(b0) * 256;
#if defined(__SSE2__)
        {
            const __m128 vsmin = _mm_set1_ps(smin), vsmax = _mm_set1_ps(smax), vmlo = _mm_set1_ps(mid_lo),
                         vmhi = _mm_set1_ps(mid_hi), ve = _mm_set1_ps(best.max_err), vninf = _mm_set1_ps(-INFINITY);
            const __m128 mid_empty = mid_lo > mid_hi ? _mm_castsi128_ps(_mm_set1_epi32(-1)) : _mm_setzero_ps();
            const __m128 en8 = row8 ? _mm_castsi128_ps(_mm_set1_epi32(-1)) : _mm_setzero_ps();
            const __m128 en6 = row6 ? _mm_castsi128_ps(_mm_set1_epi32(-1)) : _mm_setzero_ps();
            const __m128 vrow = _mm_set1_ps(T.val[b0]), vlim8 = _mm_set1_ps(lim8), vlim6 = _mm_set1_ps(lim6);
            for (int b1 = 0; b1 < 256; b1 += 4) {
                const __m128 imn = _mm_loadu_ps(&T.imin[row + size_t(b1)]), imx = _mm_loadu_ps(&T.imax[row + size_t(b1)]);
                const __m128 six = _mm_loadu_ps(&T.six_mask[row + size_t(b1)]);
                const __m128 lb8 = _mm_max_ps(_mm_sub_ps(vsmax, imx), _mm_sub_ps(imn, vsmin)); // = std::max(imn - lo, hi - imx)
                __m128 lb6 = _mm_max_ps(_mm_sub_ps(vmhi, imx), _mm_sub_ps(imn, vmlo));
                lb6 = _mm_or_ps(_mm_and_ps(mid_empty, vninf), _mm_andnot_ps(mid_empty, lb6));
                const __m128 lb = _mm_or_ps(_mm_and_ps(six, lb6), _mm_andnot_ps(six, lb8));
                const __m128 enabled = _mm_or_ps(_mm_and_ps(six, en6), _mm_andnot_ps(six, en8));
                __m128 pass = _mm_and_ps(enabled, _mm_cmple_ps(lb, ve));
                // Spacing bound: |e0 - e1| <= the mode's spread limit.
                const __m128 spread = _mm_andnot_ps(_mm_set1_ps(-0.0f), _mm_sub_ps(vrow, _mm_loadu_ps(&T.val[size_t(b1)])));
                pass = _mm_and_ps(pass, _mm_cmple_ps(spread, _mm_or_ps(_mm_and_ps(six, vlim6), _mm_andnot_ps(six, vlim8))));
                if (os) pass = _mm_and_ps(pass, _mm_cmple_ps(_mm_loadu_ps(&T.pal_min[row + size_t(b1)]), vsmin));
                // Probe texels (median, quartiles) against the 8 entries of 4 pairs at
                // once, with select_indices' error expression.
                for (int pr = 0; pr < 3 && _mm_movemask_ps(pass); ++pr) {
                    const __m128 vs = _mm_set1_ps(probe[pr]);
                    __m128 ok = _mm_setzero_ps();
                    for (int i = 0; i < 8; ++i) {
                        const __m128 lo = _mm_loadu_ps(&T.ent_lo[i][row + size_t(b1)]), hi = _mm_loadu_ps(&T.ent_hi[i][row + size_t(b1)]);
                        const __m128 e = _mm_max_ps(_mm_max_ps(_mm_sub_ps(hi, vs), _mm_sub_ps(vs, lo)), _mm_setzero_ps());
                        __m128 fits = _mm_cmple_ps(e, ve);
                        if (os) fits = _mm_andnot_ps(_mm_cmpgt_ps(hi, vs), fits);
                        ok = _mm_or_ps(ok, fits);
                    }
                    pass = _mm_and_ps(pass, ok);
                }
                int bits = _mm_movemask_ps(pass);
                for (int j = 0; j < 4; ++j)
                    if (bits & (1 << j)) cand[n++] = uint8_t(b1 + j);
            }
        }
#else
        for (int b1 = 0; b1 < 256; ++b1) {
            const size_t k = row + size_t(b1);
            const bool six = T.six[k] != 0;
            if (!(six ? row6 : row8)) continue;
            const float lb = six ? bound(T.imin[k], T.imax[k], mid_lo, mid_hi) : bound(T.imin[k], T.imax[k], smin, smax);
            if (lb > best.max_err) continue;
            if (std::fabs(T.val[b0] - T.val[b1]) > (six ? lim6 : lim8)) continue; // spacing bound
            if (os && T.pal_min[k] > smin) continue; // no entry at or below the block minimum
            cand[n++] = uint8_t(b1);
        }
#endif
        for (int c = 0; c < n; ++c) {
            const size_t k = row + cand[c];
            if (!detail::palette_within(T.pal[k], probe, os, best.max_err)) continue;
            detail::Selection s = detail::select_indices(T.pal[k], src, os, best.max_err);
            if (!std::isfinite(s.max_err)) continue;
            const bool tie = s.max_err == best.max_err && s.sum_sq == best.sum_sq;
            if (best_k < 0 || detail::better(s, best) || (tie && int(k) < best_k)) {
                best = s;
                best_k = int(k);
                update_mid();
            }
        }
    }
    return best_k;
}
} // namespace

BlockResult Bc4Encoder::encode_exhaustive(const float src[16], uint8_t out[8]) const {
    detail::Selection best;
    const int best_k = search_all_pairs(*tables_, src, options_.one_sided_below, best, -1);
    if (best_k < 0) { // cannot happen for UNORM/SNORM (0 / -1 entry), kept for safety
        std::memset(out, 0, 8);
        return {std::numeric_limits<float>::infinity(), 0, false};
    }
    write_block(uint8_t(best_k >> 8), uint8_t(best_k & 255), best.idx, out);
    return {best.max_err, best.sum_sq, true};
}

namespace {
// The exact result of the indices a key evaluation chose, written into `s` in place
// (a returned copy read the fresh stores back as one 16-byte load: a forwarding stall).
template <bool OneSided>
void exact_selection(const PairTables& T, const detail::Palette<1>& p, const float src[16], const detail::Bc4Keys& k, detail::Selection& s,
                     uint64_t& bits) {
#if defined(ATLAS_BC4_AVX2)
    if (T.avx2) {
        detail::bc4_exact_avx2(p, src, k, s.max_err, s.sum_sq, bits);
        return;
    }
#else
    (void)T;
#endif
    detail::bc4_exact_portable<OneSided>(p, src, k, s.max_err, s.sum_sq, bits);
}

template <bool OneSided>
bool keys_of(const PairTables& T, const detail::Palette<1>& p, const float src[16], float stop, float inc_sum, detail::Bc4Keys& k) {
#if defined(ATLAS_BC4_AVX2)
    if (T.avx2) return detail::bc4_keys_avx2<OneSided>(p, src, stop, inc_sum, k);
#else
    (void)T;
#endif
    return detail::bc4_keys<OneSided>(p, src, stop, inc_sum, k);
}
} // namespace

namespace detail::bc4 {

__attribute__((noinline)) BlockResult encode_candidates(const PairTables& T, bool snorm, const BlockOptions& options, const float src[16], uint8_t out[8]) {
    float smin, smax;
    bool finite, flat; // flat: all 16 texels have the same bits
#if defined(__SSE2__)
    {
        const __m128 a = _mm_loadu_ps(src), b = _mm_loadu_ps(src + 4), c = _mm_loadu_ps(src + 8), d = _mm_loadu_ps(src + 12);
        __m128 mn = _mm_min_ps(_mm_min_ps(a, b), _mm_min_ps(c, d)), mx = _mm_max_ps(_mm_max_ps(a, b), _mm_max_ps(c, d));
        mn = _mm_min_ps(mn, _mm_movehl_ps(mn, mn));
        mx = _mm_max_ps(mx, _mm_movehl_ps(mx, mx));
        smin = _mm_cvtss_f32(_mm_min_ss(mn, _mm_shuffle_ps(mn, mn, 1)));
        smax = _mm_cvtss_f32(_mm_max_ss(mx, _mm_shuffle_ps(mx, mx, 1)));
        const __m128 nan = _mm_or_ps(_mm_or_ps(_mm_cmpunord_ps(a, b), _mm_cmpunord_ps(c, d)), _mm_cmpunord_ps(a, c));
        finite = !_mm_movemask_ps(nan) && smin >= -1e30f && smax <= 1e30f;
        const __m128i v0 = _mm_castps_si128(_mm_set1_ps(src[0]));
        const __m128i eq = _mm_and_si128(_mm_and_si128(_mm_cmpeq_epi32(_mm_castps_si128(a), v0), _mm_cmpeq_epi32(_mm_castps_si128(b), v0)),
                                         _mm_and_si128(_mm_cmpeq_epi32(_mm_castps_si128(c), v0), _mm_cmpeq_epi32(_mm_castps_si128(d), v0)));
        flat = _mm_movemask_epi8(eq) == 0xffff;
    }
#else
    smin = src[0];
    smax = src[0];
    bool nan = std::isnan(src[0]);
    for (int t = 1; t < 16; ++t) { smin = std::min(smin, src[t]); smax = std::max(smax, src[t]); nan = nan || std::isnan(src[t]); }
    finite = !nan && smin >= -1e30f && smax <= 1e30f;
    flat = true;
    for (int t = 1; t < 16; ++t) flat = flat && std::memcmp(&src[t], &src[0], 4) == 0;
#endif
    const float scale = snorm ? 127.0f : 255.0f;
    const int lo_lim = snorm ? -127 : 0, hi_lim = snorm ? 127 : 255;
    if (flat && T.flat_ready && T.shortcuts) {
        BlockResult r;
        if (flat_from_table(T, src[0], snorm, out, r)) return r;
    }
    auto clampi = [&](int v) { return std::clamp(v, lo_lim, hi_lim); };
    // floor / ceil of a scaled extreme, in integers (clamped first: the levels are within +-255).
    auto in_range = [](float x) { return x > -1024.0f ? (x < 1024.0f ? x : 1024.0f) : -1024.0f; }; // NaN -> -1024
    auto floor_i = [&](float x) { x = in_range(x); const int i = int(x); return i - (float(i) > x ? 1 : 0); };
    auto ceil_i = [&](float x) { x = in_range(x); const int i = int(x); return i + (float(i) < x ? 1 : 0); };
    const int qlo0 = clampi(floor_i(smin * scale)), qlo1 = clampi(ceil_i(smin * scale));
    const int qhi0 = clampi(floor_i(smax * scale)), qhi1 = clampi(ceil_i(smax * scale));
    const bool os = options.one_sided_below;
    // The Reference decoder alone: every entry's interval is its exact value to ulps.
    const bool narrow = options.decoders == kReferenceOnly;
    int best_k = -1;
    detail::Selection best;
    uint64_t bits = 0;  // the winner's index field when `keyed`
    bool keyed = false; // else best.idx (select_indices)
    {
        auto byte_of = [&](int v) { return uint8_t(snorm ? uint8_t(int8_t(v)) : uint8_t(v)); };
        // Candidate pairs (each once), evaluated in order; ties keep the earlier one.
        int cands[32];
        int ncand = 0;
        auto consider = [&](int a, int b) {
            const int k = int(byte_of(a)) * 256 + int(byte_of(b));
            for (int c = 0; c < ncand; ++c)
                if (cands[c] == k) return;
            cands[ncand++] = k;
        };
        // Floor / ceil of the extremes, the 8-value mode first (Best and blocks missing the
        // bound start the exhaustive search from this incumbent: the result is the same,
        // found sooner). One-sided: also the level below the floor. The bounds are exact
        // (widened), so a minimum that sits on a level's float value can be an ulp below the
        // level itself, and without a lower endpoint such a texel would be left with the
        // constant 0.
        const int hstep = options.quality == Quality::Fast ? std::max(1, qhi1 - qhi0) : 1;
        const int h0 = os && qhi0 > lo_lim ? qhi0 - hstep : qhi0, l0 = os ? clampi(qlo0 - 1) : qlo0;
        for (int h = h0; h <= qhi1; h += hstep)
            for (int l = l0; l <= qlo1; ++l)
                if (clampi(h) > clampi(l)) consider(clampi(h), clampi(l)); // 8 interpolated values
        // The 6-value mode (plus exact extremes). Fast skips it, except for flat blocks
        // (a == b) where the 8-value mode has no pair (else they would fall to the
        // exhaustive search).
        for (int h = h0; h <= qhi1; h += hstep)
            for (int l = l0; l <= qlo1; ++l) {
                const int a = clampi(h), b = clampi(l);
                if (options.quality != Quality::Fast || os || a == b) consider(std::min(a, b), std::max(a, b));
            }
        detail::Bc4Keys keys[2];
        detail::Palette<1> pal[2];
        int cur = 0;
        if (!finite) { // NaN or huge texels: select_indices' comparisons, no keys
            for (int c = 0; c < ncand; ++c) {
                const int k = cands[c];
                detail::Selection s = detail::select_indices(T.pal[size_t(k)], src, os, best.max_err);
                if (best_k < 0 ? std::isfinite(s.max_err) : detail::better(s, best)) { best = s; best_k = k; }
            }
        } else {
            for (int c = 0; c < ncand; ++c) {
                const int k = cands[c];
                if (best_k >= 0 && T.shortcuts && narrow && k == swapped(best_k) && endpoints_only(keys[1 - cur]) && smin >= T.end_lo[k >> 8] &&
                    smax <= T.end_hi[k & 255])
                    continue; // cannot win (endpoints_only)
                entry_palette(T, k, snorm, pal[cur]);
                const auto& p = pal[cur];
                const float stop = best_k < 0 ? detail::kBc4Infeasible : keys[1 - cur].max_err;
                const float inc_sum = best_k < 0 ? INFINITY : keys[1 - cur].sum;
                // A flat block is evaluated on one texel (the same keys and sums, bc4_eval.h).
                const bool ok = flat ? (os ? detail::bc4_keys_flat<true>(p, src, stop, inc_sum, keys[cur]) : detail::bc4_keys_flat<false>(p, src, stop, inc_sum, keys[cur]))
                                     : (os ? keys_of<true>(T, p, src, stop, inc_sum, keys[cur]) : keys_of<false>(T, p, src, stop, inc_sum, keys[cur]));
                if (ok && (best_k < 0 || detail::bc4_keys_better(keys[cur], keys[1 - cur]))) {
                    best_k = k;
                    cur = 1 - cur;
                    // An exact incumbent (key errors all 0) cannot be beaten: a later candidate
                    // returns false (max error above 0, or 0 and a sum not below 0).
                    if (keys[1 - cur].max_err == 0.0f && keys[1 - cur].sum == 0.0f) break;
                }
            }
        }
        if (finite && best_k >= 0) {
            const auto& p = pal[1 - cur];
            if (flat) { // one texel stands for all 16 (the same result, bc4_eval.h)
                if (os) detail::bc4_exact_flat<true>(p, src, keys[1 - cur], best.max_err, best.sum_sq, bits);
                else detail::bc4_exact_flat<false>(p, src, keys[1 - cur], best.max_err, best.sum_sq, bits);
            } else if (os) exact_selection<true>(T, p, src, keys[1 - cur], best, bits);
            else exact_selection<false>(T, p, src, keys[1 - cur], best, bits);
            keyed = true;
        }
    }
    const bool missed = best_k < 0 || (options.max_error >= 0 && best.max_err > options.max_error);
    if (missed || options.quality == Quality::Best) {
        // The exhaustive search's incumbent is select_indices' result for the pair (its
        // result, the lexicographic minimum over all pairs, does not depend on it).
        if (best_k >= 0) best = detail::select_indices(T.pal[size_t(best_k)], src, os);
        keyed = false;
        best_k = search_all_pairs(T, src, os, best, best_k);
        if (best_k < 0) { // cannot happen for UNORM/SNORM (0 / -1 entry), kept for safety
            std::memset(out, 0, 8);
            return {std::numeric_limits<float>::infinity(), 0, false};
        }
    }
    if (keyed) write_block_bits(uint8_t(best_k >> 8), uint8_t(best_k & 255), bits, out);
    else write_block(uint8_t(best_k >> 8), uint8_t(best_k & 255), best.idx, out);
    return {best.max_err, best.sum_sq, true};
}

} // namespace detail::bc4

BlockResult Bc4Encoder::encode(const float src[16], uint8_t out[8]) const {
    return detail::bc4::encode_block(*tables_, snorm_, options_, src, out);
}

void Bc4Encoder::encode_blocks(const float* src, size_t count, uint8_t* out, BlockResult* results) const {
    detail::bc4::encode_blocks(*tables_, snorm_, options_, src, count, out, results);
}

namespace detail {
long bc4_shortcut_mismatches(bool snorm, const BlockOptions& options, const float* blocks, size_t count) {
    const BlockOptions o = bc4::encoder_options(options); // as Bc4Encoder's
    auto tables = std::make_unique<bc4::PairTables>(); // its own tables: the shortcuts are switched below
    bc4::fill_tables(*tables, snorm, o);
    bc4::PairTables& T = *tables;
    long bad = 0;
    auto same = [](const uint8_t* a, const BlockResult& x, const uint8_t* b, const BlockResult& y) {
        return std::memcmp(a, b, 8) == 0 && std::memcmp(&x.max_error, &y.max_error, 4) == 0 && std::memcmp(&x.sum_sq, &y.sum_sq, 8) == 0 &&
               x.one_sided_ok == y.one_sided_ok;
    };
    std::vector<uint8_t> run(8 * count);
    std::vector<BlockResult> run_res(count);
    bc4::encode_blocks(T, snorm, o, blocks, count, run.data(), run_res.data());
    for (size_t b = 0; b < count; ++b) {
        uint8_t with[8], without[8];
        const BlockResult x = bc4::encode_block(T, snorm, o, blocks + 16 * b, with);
        T.shortcuts = false;
        const BlockResult y = bc4::encode_block(T, snorm, o, blocks + 16 * b, without);
        T.shortcuts = true;
        bad += !same(with, x, without, y) || !same(&run[8 * b], run_res[b], without, y);
    }
    return bad;
}
} // namespace detail

} // namespace atlas::compress

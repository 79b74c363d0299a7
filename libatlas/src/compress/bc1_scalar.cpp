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

// Upper bound of code c's endpoint value under every decoder of the set, as the
// interval palette bounds it (the per-channel largest levels, the dot product's order,
// widened to bound the exact value).
float endpoint_hi(uint16_t c, const ScalarUnpack& u, const detail::ScalarTables& T) {
    return detail::widen_up((T.hi5[c >> 11] * u.weights[0] + T.hi6[(c >> 5) & 63] * u.weights[1]) + T.hi5[c & 31] * u.weights[2]);
}

// The largest-value split of v whose endpoint is <= v under every decoder: the greedy
// split subtracts in float, so its sum can land an ulp above v (then the endpoint is
// not one-sided and a block of such texels would be left with the 3-colour black);
// step down until the bound holds. Code 0 decodes to exactly 0.
uint16_t split_below(float v, const ScalarUnpack& u, const detail::ScalarTables& T) {
    if (!(v > 0)) return 0;
    int c = split(v, u, T.hi5, T.hi6, false);
    while (c > 0 && endpoint_hi(uint16_t(c), u, T) > v) {
        // Lower the last digit that is not 0 (B, then G, then R), refilling the lower ones.
        if ((c & 31) > 0) --c;
        else if (((c >> 5) & 63) > 0) c = (c - 32) | 31;
        else c = (c - 2048) | 0x7FF;
    }
    return uint16_t(c);
}

// The split of v with the R digit fixed to r (G and B greedy on the rest, clamped to
// the digit's range); `below`: step down until the endpoint is <= v under every
// decoder (returns 0xFFFF when no code of that digit is).
uint16_t split_r(float v, int r, const ScalarUnpack& u, const detail::ScalarTables& T, bool below) {
    const float* t5 = below ? T.hi5 : T.ref5;
    const float* t6 = below ? T.hi6 : T.ref6;
    float rest = v - t5[r] * u.weights[0];
    int g = 0, b = 0;
    if (rest > 0) {
        g = floor_level(t6, 64, u.weights[1], rest);
        rest -= t6[g] * u.weights[1];
        b = floor_level(t5, 32, u.weights[2], rest);
    }
    int c = (r << 11) | (g << 5) | b;
    if (below) {
        while ((c & 0x7FF) > 0 && endpoint_hi(uint16_t(c), u, T) > v) {
            if ((c & 31) > 0) --c;
            else c = (c - 32) | 31;
        }
        if (endpoint_hi(uint16_t(c), u, T) > v) return 0xFFFF;
    }
    return uint16_t(c);
}

// Candidates for a block one blend entry serves (see the caller). Coarse: for each mode,
// blend entry and R digit pair whose R part is at most `smin` under every decoder and
// within reach of G and B, the shared G, B digits of the largest split of the rest (a
// blend of equal digits is the level itself), stepped down until the entry is <= smin.
// Fine, for the four R pairs whose coarse entry came closest: G digits that differ
// between the endpoints with the same blend (their decoders disagree differently), and
// B digit pairs whose blend fills the rest.
template <class Consider>
void single_entry_candidates(const detail::ScalarTables& T, float smin, float below, Consider& consider) {
    const ScalarUnpack& u = T.unpack;
    const float w1 = u.weights[1], w2 = u.weights[2];
    const float reach = T.hi6[63] * w1 + T.hi5[31] * w2;
    struct Combo { float lo = -INFINITY; int f = 0, i = 0, r0 = 0, r1 = 0; float r_hi = 0; };
    constexpr int kTop = 4;
    Combo top[kTop];
    auto entry_bounds = [&](uint16_t c0, uint16_t c1, int i, float& lo, float& hi) {
        detail::Palette<1> p;
        detail::scalar_interval_palette(T, c0, c1, p);
        lo = p.lo[i][0];
        hi = p.hi[i][0];
    };
    for (int f = 0; f < 2; ++f)
        for (int i = 2; i < (f == 1 ? 4 : 3); ++i) // the blends: 2, 3 (four colours), 2 (three colours)
            for (int r0 = 0; r0 < 32; ++r0)
                for (int r1 = 0; r1 < 32; ++r1) {
                    if (f == 1 ? !(r0 > r1) : !(r0 < r1)) continue; // the codes' order picks the mode
                    float r_hi = -INFINITY;
                    for (int di = 0; di < kDecoderCount; ++di)
                        if (T.in_set[di]) r_hi = std::max(r_hi, T.r[di][f][r0][r1][i]);
                    if (!(r_hi <= smin) || r_hi < smin - reach - below) continue;
                    const float rest = smin - r_hi;
                    const int g = floor_level(T.hi6, 64, w1, rest);
                    const int b = floor_level(T.hi5, 32, w2, rest - T.hi6[g] * w1);
                    for (int alt = 0; alt < 2; ++alt) {
                        const int start = alt == 0 ? (g << 5) | b : g > 0 ? ((g - 1) << 5) | 31 : -1;
                        for (int gb = start; gb >= 0 && gb >= start - 4; --gb) { // step down until <= smin
                            const uint16_t c0 = uint16_t((r0 << 11) | gb), c1 = uint16_t((r1 << 11) | gb);
                            float lo, hi;
                            entry_bounds(c0, c1, i, lo, hi);
                            if (!(hi <= smin)) continue;
                            consider(c0, c1);
                            // Keep the kTop best distinct combos (by the entry's lower bound), sorted.
                            int at = 0;
                            while (at < kTop && top[at].lo >= lo && !(top[at].f == f && top[at].i == i && top[at].r0 == r0 && top[at].r1 == r1)) ++at;
                            if (at < kTop && !(top[at].f == f && top[at].i == i && top[at].r0 == r0 && top[at].r1 == r1)) {
                                for (int k = kTop - 1; k > at; --k) top[k] = top[k - 1];
                                top[at] = Combo{lo, f, i, r0, r1, r_hi};
                            }
                            break;
                        }
                    }
                }
    // Pairs sharing an R digit (R then exact in every decoder, G's blend carries the
    // value): the digits of smin's round-down and the one below, every mode and blend.
    Combo shared[6];
    int nshared = 0;
    {
        const int ra = split_below(smin, u, T) >> 11;
        for (int r = ra; r >= std::max(0, ra - 1); --r) {
            const uint16_t c = split_r(smin, r, u, T, true);
            if (c == 0xFFFF) continue;
            float lo, hi;
            entry_bounds(c, c, 0, lo, hi);
            float r_hi = -INFINITY;
            for (int di = 0; di < kDecoderCount; ++di)
                if (T.in_set[di]) r_hi = std::max(r_hi, T.r[di][0][r][r][0]);
            for (int f = 0; f < 2; ++f)
                for (int i = 2; i < (f == 1 ? 4 : 3); ++i) shared[nshared++] = Combo{lo, f, i, r, r, r_hi};
        }
    }
    Combo all[kTop + 6];
    int nall = 0;
    for (const Combo& c : top) all[nall++] = c;
    for (int k = 0; k < nshared; ++k) all[nall++] = shared[k];
    for (int ci = 0; ci < nall; ++ci) {
        const Combo& c = all[ci];
        if (!(c.lo > -INFINITY)) continue;
        // The blend's weights of endpoint 0 and 1, times 6 (integers).
        const int a0 = c.f == 0 ? 3 : c.i == 2 ? 4 : 2, a1 = 6 - a0;
        const float rest = smin - c.r_hi;
        const float g_level = rest / w1 * 63.0f; // the G level (Reference) the blend should reach
        const int gc = int(g_level);
        for (int g0 = std::max(0, gc - 8); g0 <= std::min(63, gc + 8); ++g0) {
            // a0 g0 + a1 g1 ~ 6 gc: both roundings of g1.
            const float g1f = (6.0f * float(gc) - float(a0 * g0)) / float(a1);
            for (int g1 = int(std::floor(g1f)) - 1; g1 <= int(std::ceil(g1f)) + 1; ++g1) {
                if (g1 < 0 || g1 > 63) continue;
                // The entry with B digits 0 under every decoder at once (the channels'
                // maxima can come from different decoders): what B must add.
                float lo0, hi0;
                const uint16_t z0 = uint16_t((c.r0 << 11) | (g0 << 5)), z1 = uint16_t((c.r1 << 11) | (g1 << 5));
                entry_bounds(z0, z1, c.i, lo0, hi0);
                const float rest_b = smin - hi0;
                if (rest_b < 0) continue;
                const float b_level = std::min(31.0f, rest_b / w2 * 31.0f);
                for (int b0 = 0; b0 < 32; ++b0) {
                    const float b1f = (6.0f * b_level - float(a0 * b0)) / float(a1);
                    const int b1 = int(std::floor(b1f));
                    for (int db = 1; db >= -1; --db) {
                        const int bb = b1 + db;
                        if (bb < 0 || bb > 31) continue;
                        const uint16_t c0 = uint16_t((c.r0 << 11) | (g0 << 5) | b0), c1 = uint16_t((c.r1 << 11) | (g1 << 5) | bb);
                        if (c.f == 1 ? !(c0 > c1) : !(c0 <= c1)) continue;
                        float lo, hi;
                        entry_bounds(c0, c1, c.i, lo, hi);
                        if (hi <= smin && lo > c.lo) consider(c0, c1);
                    }
                }
            }
        }
    }
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
        lows.add(split_below(smin - m, u, T));
        highs.add(split_below(smax - m, u, T));
        if (options.quality != Quality::Fast) { // Nubis: move the high endpoint down
            highs.add(split_below(sorted[13] - m, u, T));
            highs.add(split_below(sorted[10] - m, u, T));
        }
        if (options.quality == Quality::Best)
            for (int t = 0; t < 16; ++t) highs.add(split_below(src[t] - m, u, T));
    }
    if (!options.one_sided_below) {
        lows.add(split(smin, u, T.ref5, T.ref6, true));
        highs.add(split(smax, u, T.ref5, T.ref6, true));
    }
    // Pairs sharing one R digit: the R channel is then constant over the palette, so
    // its entries are the endpoint's R level under every decoder (the 8-bit decoders
    // round R interpolants differently, by up to ~1/255 of the range), and G carries
    // the block's variation (G's range covers an R step). The digits of the minimum's
    // round-down and the one below.
    if (options.one_sided_below && options.quality != Quality::Fast && !T.conformant) {
        const int r_min = lows.v[0] >> 11;
        for (int r = r_min; r >= std::max(0, r_min - 1); --r) {
            const uint16_t lo_c = split_r(smin, r, u, T, true);
            if (lo_c == 0xFFFF) continue;
            lows.add(lo_c);
            for (float x : {smax, sorted[13], sorted[10]}) {
                const uint16_t hi_c = split_r(x, r, u, T, true);
                if (hi_c != 0xFFFF) highs.add(hi_c);
            }
        }
    }
    highs.sort_unique();
    lows.sort_unique();

    detail::Selection best;
    uint16_t b0 = 0, b1 = 0;
    bool have = false;
    // Pairs already evaluated (the candidate generators repeat many): a small ring.
    uint32_t seen[32];
    int nseen = 0;
    auto consider = [&](uint16_t c0, uint16_t c1) {
        const uint32_t key = (uint32_t(c0) << 16) | c1;
        for (int i = 0; i < std::min(nseen, 32); ++i)
            if (seen[i] == key) return;
        seen[nseen++ % 32] = key;
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
    // The constant block of the round-down of the minimum: one-sided by construction
    // (a 3-colour pair of equal codes decodes its endpoints and midpoint to the
    // endpoint's value under every model), so a one-sided block's error never exceeds
    // the block's spread plus one endpoint step, whatever the other candidates do.
    consider(lows.v[0], lows.v[0]);
    for (int i = 0; i < highs.n; ++i)
        for (int j = 0; j < lows.n; ++j) both(highs.v[i], lows.v[j]);
    // Retargeting: an entry k of the palette is a fixed blend fa*u + fb*v of the endpoint
    // values; for every distinct texel value s and entry k, move one endpoint (the other
    // fixed) so that entry k lands just below s, by the entry's current excess of its
    // upper bound over its Reference value (the other decoders' rounding). One-sided
    // optima sit entries just below texel values, which the extreme-based candidates
    // above rarely hit (a ramp's texels take 4-7 distinct values).
    const int rounds = options.quality == Quality::Fast ? 0 : options.quality == Quality::Normal ? 1 : 4;
    float distinct[16];
    int nd = 0;
    for (int t = 0; t < 16; ++t)
        if (nd == 0 || sorted[t] != distinct[nd - 1]) distinct[nd++] = sorted[t];
    const int kBelow = options.quality == Quality::Best ? 2 : 1;
    // `focused`: only the texels whose error is at least half the block's (those an entry
    // placed just below would help most), for Normal's single round.
    auto retarget = [&](int nrounds, bool focused) {
        for (int round = 0; round < nrounds && have; ++round) {
            const uint16_t k0 = b0, k1 = b1;
            float targets[16];
            int nt = 0;
            if (focused) {
                detail::Palette<1> pb;
                detail::scalar_interval_palette(T, k0, k1, pb);
                for (int t = 0; t < 16; ++t)
                    if (src[t] - pb.lo[best.idx[t]][0] >= 0.5f * best.max_err && std::find(targets, targets + nt, src[t]) == targets + nt)
                        targets[nt++] = src[t];
            } else {
                std::copy(distinct, distinct + nd, targets);
                nt = nd;
            }
            // Both orders of the two codes: the 4-colour geometry of (max, min) and the
            // 3-colour one of (min, max), whichever mode the incumbent is in.
            for (int mode = 0; mode < 2; ++mode) {
                const uint16_t c0 = mode == 1 ? std::max(k0, k1) : std::min(k0, k1), c1 = mode == 1 ? std::min(k0, k1) : std::max(k0, k1);
                if (mode == 1 && c0 == c1) continue; // no 4-colour order of equal codes
                detail::Palette<1> p;
                detail::scalar_interval_palette(T, c0, c1, p);
                const bool four = c0 > c1;
                const float uv = p.ref[0][0], vv = p.ref[1][0];
                const int n = four ? 4 : 3;
                const float fa[4] = {1.0f, 0.0f, four ? 2.0f / 3.0f : 0.5f, 1.0f / 3.0f};
                const float fb[4] = {0.0f, 1.0f, four ? 1.0f / 3.0f : 0.5f, 2.0f / 3.0f};
                // Move endpoint `e` (0: c0, 1: c1) to code c; the code below too (the
                // round-down of a blend can land an ulp above its target).
                // Only this mode's order: the other mode has its own geometry pass.
                auto pair = [&](uint16_t a, uint16_t b) {
                    if (four ? a > b : a <= b) consider(a, b);
                };
                auto move = [&](int e, uint16_t c, float x = -1.0f) {
                    const int other_r = (e == 0 ? c1 : c0) >> 11;
                    if (x >= 0 && options.one_sided_below && (c >> 11) != other_r) { // also with the other endpoint's R digit
                        const uint16_t same = split_r(x, other_r, u, T, false);
                        if (e == 0) pair(same, c1);
                        else pair(c0, same);
                    }
                    for (int d = 0; d < kBelow && c >= d; ++d) {
                        const uint16_t cd = uint16_t(c - d);
                        if (e == 0) pair(cd, c1);
                        else pair(c0, cd);
                    }
                };
                for (int t = 0; t < nt; ++t)
                    for (int i = 0; i < n; ++i) {
                        const float excess = p.hi[i][0] - p.ref[i][0], target = targets[t] - excess;
                        // Endpoints: the round-down under every decoder (plus Conformant's tolerance).
                        const float at_end = targets[t] - (T.conformant ? excess : 0.0f);
                        if (i == 0) move(0, split_below(at_end, u, T));
                        else if (i == 1) move(1, split_below(at_end, u, T));
                        else {
                            const float x0 = (target - fb[i] * vv) / fa[i], x1 = (target - fa[i] * uv) / fb[i];
                            if (x0 >= 0 && x0 <= u.max_value) move(0, split(x0, u, T.ref5, T.ref6, false), x0);
                            if (x1 >= 0 && x1 <= u.max_value) move(1, split(x1, u, T.ref5, T.ref6, false), x1);
                        }
                    }
            }
            if (k0 == b0 && k1 == b1) break;
        }
    };
    // Few clusters of values (a ramp along a block axis has 4 distinct values, a slightly
    // tilted one 4 tight pairs): the one-sided minimax fit of evenly spaced entries
    // e + k g to the clusters in order (cluster j, values [lo_j, hi_j], on entry k_j).
    // For a fixed g the best e is min_j (lo_j - k_j g) and the error
    // max_j (hi_j - k_j g) - e is convex in g, so the optimum is at a crossing of two of
    // those lines. The endpoints are then rounded down (and one code lower).
    float fit_floor = INFINITY; // the smallest error of a fit with exact entries (not a proof: a guide)
    if (options.one_sided_below && options.quality != Quality::Fast && nd >= 2) {
        // Cluster positions per assignment: 4-colour (all, one blend unused, an endpoint
        // unused: the top above the block's maximum or the bottom below its minimum),
        // the 3-colour mode (a == 3), and 4-colour endpoints only.
        // The last one, both blends only, is for blocks at an R digit's boundary: the
        // 8-bit decoders put the R levels on either side ~1/655 of the range above and
        // below Reference's, and the blends of the two digits ~1/1980.
        static constexpr int kAssign[8][4] = {{0, 1, 2, 3}, {0, 1, 3, 0}, {0, 2, 3, 0}, {0, 1, 2, 0}, {0, 3, 0, 0}, {0, 1, 2, 0}, {1, 2, 3, 0}, {1, 2, 0, 0}};
        static constexpr int kGroups[8] = {4, 3, 3, 3, 2, 3, 3, 2};
        for (int a = 0; a < 8; ++a) {
            const int* k = kAssign[a];
            const int groups = kGroups[a];
            if (groups > nd || (nd <= 4 && groups != nd && a != 7)) continue;
            // Split the sorted distinct values at the groups - 1 largest gaps.
            int cut[4] = {nd, nd, nd, nd}, ncut = 0; // cut[c]: first index of group c + 1
            if (a == 7) { // both blends (equal spacing): the cut that balances the two groups' widths
                int at = 1;
                for (int t = 2; t < nd; ++t)
                    if (std::max(distinct[t - 1] - distinct[0], distinct[nd - 1] - distinct[t]) <
                        std::max(distinct[at - 1] - distinct[0], distinct[nd - 1] - distinct[at]))
                        at = t;
                cut[ncut++] = at;
            }
            for (int c = ncut; c < groups - 1; ++c) {
                int at = -1;
                for (int t = 1; t < nd; ++t) {
                    bool used = false;
                    for (int q = 0; q < ncut; ++q) used |= cut[q] == t;
                    if (!used && (at < 0 || distinct[t] - distinct[t - 1] > distinct[at] - distinct[at - 1])) at = t;
                }
                cut[ncut++] = at;
            }
            for (int i = 1; i < ncut; ++i) // at most 3 cuts (std::sort here trips GCC 12's -Warray-bounds under ASan)
                for (int j = i; j > 0 && cut[j - 1] > cut[j]; --j) std::swap(cut[j - 1], cut[j]);
            float glo[4], ghi[4];
            for (int j = 0, t0 = 0; j < groups; ++j) {
                const int t1 = j < ncut ? cut[j] : nd;
                glo[j] = distinct[t0];
                ghi[j] = distinct[t1 - 1];
                t0 = t1;
            }
            // Entry of the palette that cluster j's position k serves: 4-colour (top, bottom)
            // has entries top, bottom, (2 top + bottom) / 3, (top + 2 bottom) / 3; the
            // 3-colour (bottom, top) has bottom, top, the midpoint.
            const bool three = a == 3;
            auto entry_of = [&](int kk) { return three ? (kk == 0 ? 0 : kk == 1 ? 2 : 1) : (kk == 0 ? 1 : kk == 1 ? 3 : kk == 2 ? 2 : 0); };
            // Up to three passes: the plain fit, then the fit with each cluster shifted by its
            // entry's decoder spread in the previous pass's pair (upper bound above the Reference value
            // must stay below the cluster; the lower bound adds to the error).
            float up[4] = {0, 0, 0, 0}, down[4] = {0, 0, 0, 0};
            uint16_t last[3] = {0, 0, 0};
            int r_prev = -1; // the shared R digit of the previous pass's pair
            for (int pass = 0; pass < 3; ++pass) {
                auto err_at = [&](float g, float& e) {
                    float lo_r = INFINITY, hi_r = -INFINITY;
                    for (int j = 0; j < groups; ++j) {
                        lo_r = std::min(lo_r, glo[j] - up[j] - float(k[j]) * g);
                        hi_r = std::max(hi_r, ghi[j] + down[j] - float(k[j]) * g);
                    }
                    e = lo_r;
                    return hi_r - lo_r;
                };
                float best_g = 0, best_err = INFINITY;
                for (int i = 0; i < groups; ++i)
                    for (int j = i + 1; j < groups; ++j)
                        for (float x : {ghi[j] + down[j] - ghi[i] - down[i], glo[j] - up[j] - glo[i] + up[i], ghi[j] + down[j] - glo[i] + up[i],
                                        glo[j] - up[j] - ghi[i] - down[i]}) {
                            float e;
                            const float g = x / float(k[j] - k[i]), err = err_at(g, e);
                            if (g >= 0 && err < best_err) { best_err = err; best_g = g; }
                        }
                if (pass == 0) fit_floor = std::min(fit_floor, best_err);
                // The fit's error is that of exact Reference entries at any real positions: a
                // palette of this assignment does no better, so skip it when it cannot win.
                if (have && !(best_err < best.max_err)) break;
                float e;
                err_at(best_g, e);
                const float top = e + (three ? 2.0f : 3.0f) * best_g;
                if (!(e >= 0) || !(top <= u.max_value)) break;
                // The bottom: its round-down under every decoder; after the first pass (the
                // cluster bounds already shifted by the entries' spreads) also its Reference
                // round-down with the previous pair's R digit, which keeps R shared.
                uint16_t cv = split_below(e, u, T);
                if (pass > 0 && r_prev >= 0 && r_prev != (cv >> 11)) {
                    const uint16_t cs = split_r(e, r_prev, u, T, false);
                    detail::Palette<1> ps;
                    detail::scalar_interval_palette(T, cs, cs, ps);
                    if (ps.ref[0][0] <= e && ps.ref[0][0] >= e - T.endpoint_slack) cv = cs;
                }
                // The top endpoint also with the bottom's R digit (R then exact in every decoder).
                const uint16_t tops[2] = {split(top, u, T.ref5, T.ref6, false), split_r(top, cv >> 11, u, T, false)};
                if (pass > 0 && tops[0] == last[0] && tops[1] == last[1] && cv == last[2]) break; // converged
                last[0] = tops[0];
                last[1] = tops[1];
                last[2] = cv;
                for (int t = 0; t < 2; ++t) {
                    const uint16_t cu = tops[t];
                    if (t == 1 && cu == tops[0]) break;
                    for (int du = 0; du < 2 && cu >= du; ++du)
                        for (int dv = 0; dv < 2 && cv >= dv; ++dv) {
                            const uint16_t x = uint16_t(cu - du), y = uint16_t(cv - dv);
                            if (three) consider(std::min(x, y), std::max(x, y)); // the mode the fit is for
                            else if (x != y) consider(std::max(x, y), std::min(x, y));
                        }
                }
                // Spreads for the next pass: of the pair with the shared R digit, unless that
                // digit cannot reach the top (G and B clamped at their largest levels) or the
                // top's own digit does better (the blends of two digits can agree better).
                detail::Palette<1> pt;
                detail::scalar_interval_palette(T, tops[1], tops[1], pt);
                const bool clamped = pt.ref[0][0] < top - T.endpoint_slack;
                uint16_t cu = clamped ? tops[0] : tops[1];
                detail::Palette<1> p;
                float pe = INFINITY;
                if (three ? cv <= cu : cu > cv) {
                    detail::scalar_interval_palette(T, three ? cv : cu, three ? cu : cv, p);
                    pe = detail::select_indices(p, src, true).max_err;
                }
                if (!clamped && tops[0] != tops[1] && (three ? cv <= tops[0] : tops[0] > cv)) {
                    detail::Palette<1> q;
                    detail::scalar_interval_palette(T, three ? cv : tops[0], three ? tops[0] : cv, q);
                    if (detail::select_indices(q, src, true, pe).max_err < pe) { cu = tops[0]; p = q; }
                }
                if (three ? !(cv <= cu) : !(cu > cv)) break;
                r_prev = (cu >> 11) == (cv >> 11) ? (cv >> 11) : -1;
                for (int j = 0; j < groups; ++j) {
                    const int i = entry_of(k[j]);
                    up[j] = p.hi[i][0] - p.ref[i][0];
                    down[j] = p.ref[i][0] - p.lo[i][0];
                }
            }
        }
    }
    // Near-constant blocks (spread under the error so far): one palette entry can
    // serve every texel, and then the error is the spread plus that entry's decoder
    // disagreement, which the R channel dominates (w_r = 1; the 8-bit decoders' R levels
    // sit up to ~1/255 off Reference's). A blend of two R digits often lands where the
    // decoders agree far better than on any single endpoint, so try every blend entry of
    // every R pair just below the minimum, G and B shared by both endpoints (their blend
    // is then the level itself) and split from the rest. (Under half the error missed
    // blocks at an R digit's boundary whose two blends beat the fits, e.g. 3.7 m of spread
    // at 6.7 m against an optimum of 3.1 m.)
    if (options.one_sided_below && options.quality != Quality::Fast && !T.conformant && have && smax - smin < best.max_err)
        single_entry_candidates(T, smin, 0.5f * best.max_err, consider);
    // Normal retargets only blocks well above the exact-entry fit (twice it plus the
    // endpoint slack: the decoders' disagreement on an endpoint and one step), and not
    // under Conformant, whose tolerance (not the entries' positions) sets the error: most
    // blocks are done by then.
    const bool normal_skips = options.quality == Quality::Normal &&
                              (T.conformant || (options.one_sided_below && best.max_err <= 2.0f * fit_floor + T.endpoint_slack));
    if (!normal_skips) retarget(rounds, options.quality == Quality::Normal);
    const bool missed = !have || (options.max_error >= 0 && best.max_err > options.max_error);
    // Nudge both endpoint codes by a few units (neighbouring codes are neighbouring
    // values, and the decoders round neighbours differently), until nothing improves.
    auto nudge = [&](int radius, int nrounds) {
        for (int round = 0; round < nrounds && have; ++round) {
            const uint16_t k0 = b0, k1 = b1;
            for (int d0 = -radius; d0 <= radius; ++d0)
                for (int d1 = -radius; d1 <= radius; ++d1) {
                    const int a = int(k0) + d0, b = int(k1) + d1;
                    if (a < 0 || b < 0 || a > 65535 || b > 65535) continue;
                    both(uint16_t(a), uint16_t(b));
                }
            if (k0 == b0 && k1 == b1) break;
        }
    };
    if (options.quality == Quality::Best || missed) {
        if (missed && rounds < 4) retarget(4, false);
        nudge(3, 4);
    } else if (options.quality == Quality::Normal && options.one_sided_below && !T.conformant) {
        nudge(2, 2);
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

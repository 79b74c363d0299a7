// BC1 RGB encoder: principal-axis endpoints, then +-1 hill climbing on the 565
// endpoints under the decoder-set objective: max error, then squared error; or, given
// a bound (max_error), the squared error among the choices within it.
#include "atlas/compress/bc1.h"

#include "bc1_eval.h"
#include "bc1_palette.h"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace atlas::compress {

namespace {

struct Rgb565 { int c[3]; };

uint16_t pack(const Rgb565& e) { return uint16_t((e.c[0] << 11) | (e.c[1] << 5) | e.c[2]); }

Rgb565 quantize(const double v[3]) {
    Rgb565 e;
    const int m[3] = {31, 63, 31};
    for (int c = 0; c < 3; ++c) e.c[c] = std::clamp(int(std::lround(std::clamp(v[c], 0.0, 1.0) * m[c])), 0, m[c]);
    return e;
}

struct Candidate {
    uint16_t c0 = 0, c1 = 0;
    detail::Selection sel;
    bool valid = false;
};

// select_indices<3> with AVX2 where the CPU has it (bc1_eval.h: the same result).
bool use_avx2() {
    static const bool yes = detail::bc1_cpu_has_avx2();
    return yes;
}

class Search {
public:
    // Given a bound (max_error >= 0), the search minimises the squared error within it
    // (better_within); without one, the max error first (better).
    Search(const float* src, const BlockOptions& o)
        : src_(src), o_(o), budget_(o.max_error >= 0 ? o.max_error : -1.0f), planes_(src), avx2_(use_avx2()) {}

    // Evaluates the ordered pair (c0, c1); keeps it when better. A pair evaluated before
    // in this block is skipped: it was not better than the incumbent then, and the
    // incumbent has only improved since (so skipping changes no result).
    void try_pair(uint16_t c0, uint16_t c1) {
        if (seen(c0, c1)) return;
        // A pair whose block max error exceeds `stop` cannot win (better_within): the
        // incumbent's max error, or the bound once the incumbent is within it. Against an
        // incumbent within the bound a pair must also have the smaller sum (or an equal
        // one), so its selection stops once its sum passes the incumbent's.
        const bool within = within_bound();
        const float stop = !best.valid ? INFINITY : within ? budget_ : best.sel.max_err;
        const double sum_stop = within ? best.sel.sum_sq : INFINITY;
        detail::Selection s;
#if defined(ATLAS_BC1_AVX2)
        if (avx2_) {
            detail::Bc1PaletteCm p;
            detail::bc1_interval_palette_cm(c0, c1, o_.decoders, p);
            s = o_.one_sided_below ? detail::bc1_select_avx2<true>(p, planes_, stop, budget_, sum_stop)
                                   : detail::bc1_select_avx2<false>(p, planes_, stop, budget_, sum_stop);
        } else
#endif
        {
            detail::Palette<3> p;
            detail::bc1_interval_palette(c0, c1, o_.decoders, p);
            s = detail::select_indices(p, src_, o_.one_sided_below, stop, budget_, sum_stop);
        }
        if (!std::isfinite(s.max_err)) return;
        if (!best.valid || detail::better_within(s, best.sel, budget_)) { best.c0 = c0; best.c1 = c1; best.sel = s; best.valid = true; }
    }
    // The unordered pair in one mode: 4 colours (c0 > c1; 3 when equal) or 3 plus black.
    void try_mode(uint16_t a, uint16_t b, bool four) {
        if (four) try_pair(std::max(a, b), std::min(a, b));
        else try_pair(std::min(a, b), std::max(a, b));
    }
    // Both modes of an unordered pair.
    void try_both(uint16_t a, uint16_t b) {
        try_pair(std::max(a, b), std::min(a, b)); // 4 colours (3 when equal)
        try_pair(std::min(a, b), std::max(a, b)); // 3 colours + black
    }
    // Whether the incumbent is within a bound: only then do the squared-error moves below
    // apply. Until then the search visits exactly the pairs the unbounded search visits, so
    // a bound that search meets is always met.
    bool within_bound() const { return budget_ >= 0 && best.valid && best.sel.max_err <= budget_; }

    // Rounds of +-1 moves on each channel of each endpoint, in both modes. Within a bound
    // only the move against the squared error's gradient (of the least-squares model of
    // fit_squared_error at the incumbent's indices) is tried per channel: half the pairs,
    // where every pair within the bound costs its full squared-error pass; and, below
    // Best, after the first round only in the incumbent's mode (encoder version 8: half the
    // render's evaluations within a bound were the other mode's, for 0.7406 -> 0.7636 RMSE
    // and 12% of its time; docs/PERFORMANCE.md).
    void refine(int rounds) {
        for (int r = 0; r < rounds && best.valid; ++r) {
            const uint16_t b0 = best.c0, b1 = best.c1;
            const uint32_t before_key = (uint32_t(b0) << 16) | b1;
            int descent[2][3] = {{0, 0, 0}, {0, 0, 0}}; // 0: both directions
            if (within_bound()) squared_error_descent(descent);
            for (int end = 0; end < 2; ++end)
                for (int ch = 0; ch < 3; ++ch)
                    for (int dir = -1; dir <= 1; dir += 2) {
                        if (descent[end][ch] != 0 && dir != descent[end][ch]) continue;
                        uint16_t e[2] = {b0, b1};
                        const int shift = ch == 0 ? 11 : ch == 1 ? 5 : 0, m = ch == 1 ? 63 : 31;
                        int v = (e[end] >> shift) & m;
                        v += dir;
                        if (v < 0 || v > m) continue;
                        e[end] = uint16_t((e[end] & ~(m << shift)) | (v << shift));
                        if (r >= 1 && within_bound() && o_.quality != Quality::Best) try_mode(e[0], e[1], b0 > b1); // the incumbent's mode
                        else try_both(e[0], e[1]);
                    }
            if (((uint32_t(best.c0) << 16) | best.c1) == before_key) break; // local optimum
        }
    }

    // The incumbent's weight on c0 per texel (1, 0, 2/3, 1/3 in 4-colour mode; 1, 0, 1/2 in
    // 3-colour mode); -1 for a black texel (3-colour index 3), which no endpoint moves.
    void incumbent_weights(double a[16]) const {
        const bool four = best.c0 > best.c1;
        for (int t = 0; t < 16; ++t) {
            const int i = best.sel.idx[t];
            a[t] = !four && i == 3 ? -1.0 : i == 0 ? 1.0 : i == 1 ? 0.0 : four ? (i == 2 ? 2.0 / 3.0 : 1.0 / 3.0) : 0.5;
        }
    }
    // The sign of the move that lowers the squared error per endpoint channel, from the
    // gradient of sum_t (a_t e0 + (1 - a_t) e1 - x_t)^2 at the incumbent's endpoints.
    void squared_error_descent(int descent[2][3]) const {
        double a[16];
        incumbent_weights(a);
        float pal[4][3];
        bc1_palette(best.c0, best.c1, Decoder::Reference, pal);
        for (int c = 0; c < 3; ++c) {
            double g0 = 0, g1 = 0;
            for (int t = 0; t < 16; ++t) {
                if (a[t] < 0) continue;
                const double r = a[t] * pal[0][c] + (1.0 - a[t]) * pal[1][c] - src_[3 * t + c];
                g0 += a[t] * r, g1 += (1.0 - a[t]) * r;
            }
            descent[0][c] = g0 > 0 ? -1 : g0 < 0 ? 1 : 0;
            descent[1][c] = g1 > 0 ? -1 : g1 < 0 ? 1 : 0;
        }
    }

    // Within a bound: the endpoints that minimise the squared error for the incumbent's
    // indices (least squares per channel, each texel's weight on c0 being 1, 0, 2/3, 1/3 in
    // 4-colour mode and 1, 0, 1/2 in 3-colour mode, black texels left out), rounded to 565 and
    // tried in both modes, while that improves the incumbent (the cluster-fit step of
    // squish and rgbcx; the max-error-first search has no use for it).
    void fit_squared_error(int steps) {
        for (int it = 0; it < steps && within_bound(); ++it) {
            double w[16];
            incumbent_weights(w);
            double aa = 0, ab = 0, bb = 0, ax[3] = {0, 0, 0}, bx[3] = {0, 0, 0};
            for (int t = 0; t < 16; ++t) {
                if (w[t] < 0) continue; // black
                const double a = w[t], b = 1.0 - a;
                aa += a * a, ab += a * b, bb += b * b;
                for (int c = 0; c < 3; ++c) ax[c] += a * src_[3 * t + c], bx[c] += b * src_[3 * t + c];
            }
            const double det = aa * bb - ab * ab;
            if (!(det > 1e-9)) return; // every texel on one entry: nothing to fit
            double e0[3], e1[3];
            for (int c = 0; c < 3; ++c) {
                e0[c] = (bb * ax[c] - ab * bx[c]) / det;
                e1[c] = (aa * bx[c] - ab * ax[c]) / det;
            }
            const uint16_t before0 = best.c0, before1 = best.c1;
            try_both(pack(quantize(e0)), pack(quantize(e1)));
            if (best.c0 == before0 && best.c1 == before1) return; // no better pair
        }
    }

    Candidate best;

private:
    // Open addressing over the pairs evaluated so far (key + 1, 0 = empty); once the
    // table is half full, further pairs are evaluated without being remembered.
    bool seen(uint16_t c0, uint16_t c1) {
        const uint32_t key = ((uint32_t(c0) << 16) | c1) + 1u; // 0 stays free (wraps only for 65535, 65535)
        if (key == 0) return false;
        uint32_t h = (key * 0x9E3779B1u) >> 24;
        for (;; h = (h + 1) & 255) {
            if (seen_[h] == key) return true;
            if (seen_[h] == 0) break;
        }
        if (nseen_ < 128) { seen_[h] = key; ++nseen_; }
        return false;
    }

    const float* src_;
    const BlockOptions& o_;
    float budget_;
    detail::Bc1Planes planes_;
    bool avx2_;
    uint32_t seen_[256] = {};
    int nseen_ = 0;
};

// The search for one block (encode_bc1_block's, without the flat-block memo).
BlockResult search_block(const float rgb[48], const BlockOptions& options, uint8_t out[8]);

// The last flat block (16 texels with the same bits) this thread encoded, and its
// options and result. Flat blocks come in runs of one colour (sky, clamped maps: 77%
// of the cloud render's flat blocks repeat the flat block before them, 94% of the
// weather map's), and the search is a pure function of the block and the options, so
// a repeat is answered from here with the same bytes on any thread and in any order.
struct FlatMemo {
    bool valid = false;
    uint32_t colour[3];
    BlockOptions options;
    uint8_t out[8];
    BlockResult result;
};
thread_local FlatMemo flat_memo;

} // namespace

BlockResult encode_bc1_block(const float rgb[48], const BlockOptions& options, uint8_t out[8]) {
    uint32_t bits[48];
    std::memcpy(bits, rgb, sizeof bits);
    bool flat = true;
    for (int t = 1; t < 16 && flat; ++t) flat = bits[3 * t] == bits[0] && bits[3 * t + 1] == bits[1] && bits[3 * t + 2] == bits[2];
    if (!flat) return search_block(rgb, options, out);
    FlatMemo& m = flat_memo;
    if (m.valid && std::memcmp(m.colour, bits, sizeof m.colour) == 0 && m.options == options) {
        std::memcpy(out, m.out, 8);
        return m.result;
    }
    const BlockResult r = search_block(rgb, options, out);
    m.valid = true;
    std::memcpy(m.colour, bits, sizeof m.colour);
    m.options = options;
    std::memcpy(m.out, out, 8);
    m.result = r;
    return r;
}

namespace {
// Given a bound, a block whose squared error (summed over its 16 texels and 3 channels,
// in [0, 1] units; 0.03 is 6.4 levels of 255 RMS) stays above this after the search
// gets a second search from two clusters (two_cluster_endpoints). The weather map's panel
// edges (grey beside white) end there in the max-error starts' basin.
constexpr double kSecondStartSumSq = 0.03;

// The texels split in two at the widest gap between their projections on the principal
// axis (search_block's `proj`; ties by texel order), each side's mean an endpoint (a: the
// upper side). False when every projection is the same.
bool two_cluster_endpoints(const float rgb[48], const double proj[16], double a[3], double b[3]) {
    int order[16];
    for (int t = 0; t < 16; ++t) order[t] = t;
    std::sort(order, order + 16, [&](int x, int y) { return proj[x] < proj[y] || (proj[x] == proj[y] && x < y); });
    int cut = 0;
    double gap = 0;
    for (int k = 1; k < 16; ++k)
        if (proj[order[k]] - proj[order[k - 1]] > gap) { gap = proj[order[k]] - proj[order[k - 1]]; cut = k; }
    if (cut == 0) return false;
    for (int c = 0; c < 3; ++c) a[c] = b[c] = 0;
    for (int k = 0; k < 16; ++k)
        for (int c = 0; c < 3; ++c) (k < cut ? b : a)[c] += rgb[3 * order[k] + c];
    for (int c = 0; c < 3; ++c) { b[c] /= cut; a[c] /= 16 - cut; }
    return true;
}

BlockResult search_block(const float rgb[48], const BlockOptions& options, uint8_t out[8]) {
    double mean[3] = {0, 0, 0}, lo[3] = {1e30, 1e30, 1e30}, hi[3] = {-1e30, -1e30, -1e30};
    for (int t = 0; t < 16; ++t)
        for (int c = 0; c < 3; ++c) {
            mean[c] += rgb[3 * t + c] / 16.0;
            lo[c] = std::min(lo[c], double(rgb[3 * t + c]));
            hi[c] = std::max(hi[c], double(rgb[3 * t + c]));
        }
    double cov[3][3] = {};
    for (int t = 0; t < 16; ++t)
        for (int a = 0; a < 3; ++a)
            for (int b = 0; b < 3; ++b) cov[a][b] += (rgb[3 * t + a] - mean[a]) * (rgb[3 * t + b] - mean[b]);
    double axis[3] = {hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]};
    if (axis[0] + axis[1] + axis[2] <= 0) axis[0] = axis[1] = axis[2] = 1;
    for (int it = 0; it < 4; ++it) { // power iteration, deterministic start
        double n[3];
        for (int a = 0; a < 3; ++a) n[a] = cov[a][0] * axis[0] + cov[a][1] * axis[1] + cov[a][2] * axis[2];
        double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        if (!(len > 1e-12)) break;
        for (int a = 0; a < 3; ++a) axis[a] = n[a] / len;
    }
    double len = std::sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]);
    for (double& a : axis) a /= len;
    double tmin = 1e30, tmax = -1e30, proj[16];
    for (int t = 0; t < 16; ++t) {
        double p = 0;
        for (int c = 0; c < 3; ++c) p += (rgb[3 * t + c] - mean[c]) * axis[c];
        proj[t] = p;
        tmin = std::min(tmin, p);
        tmax = std::max(tmax, p);
    }
    double e0[3], e1[3];
    for (int c = 0; c < 3; ++c) { e0[c] = mean[c] + tmax * axis[c]; e1[c] = mean[c] + tmin * axis[c]; }
    // Box diagonal `corner` (1..3: red and / or green flipped) and the principal endpoints
    // inset by f, as 565 pairs.
    auto box_corner = [&](int corner, uint16_t& pa, uint16_t& pb) {
        double a[3], b[3];
        for (int c = 0; c < 3; ++c) {
            const bool flip = c < 2 && ((corner >> c) & 1);
            a[c] = flip ? lo[c] : hi[c];
            b[c] = flip ? hi[c] : lo[c];
        }
        pa = pack(quantize(a));
        pb = pack(quantize(b));
    };
    auto inset = [&](double f, uint16_t& pa, uint16_t& pb) {
        double a[3], b[3];
        for (int c = 0; c < 3; ++c) { a[c] = e0[c] + (e1[c] - e0[c]) * f; b[c] = e1[c] + (e0[c] - e1[c]) * f; }
        pa = pack(quantize(a));
        pb = pack(quantize(b));
    };

    Search s(rgb, options);
    s.try_both(pack(quantize(e0)), pack(quantize(e1)));
    if (options.quality != Quality::Fast) {
        // The box diagonals are max-error starts: given a bound the principal start already
        // meets, the squared-error search below starts from it and an inset of it instead
        // (encoder version 8). Until a pair meets the bound, the same pairs as unbounded.
        if (!s.within_bound()) {
            s.try_both(pack(quantize(hi)), pack(quantize(lo))); // box diagonal
            for (int corner = 1; corner < 4; ++corner) { // the other box diagonals, 4-colour mode
                uint16_t pa, pb;
                box_corner(corner, pa, pb);
                if (pa != pb) s.try_pair(std::max(pa, pb), std::min(pa, pb));
            }
        }
        if (s.within_bound()) { // the principal endpoints inset by 1/16 (a squared-error start), 4 colours
            uint16_t pa, pb;
            inset(0.0625, pa, pb);
            s.try_mode(pa, pb, true);
        }
        s.fit_squared_error(1); // within a bound only: a least-squares start for the descent
        s.refine(3);
        s.fit_squared_error(3);
        double a[3], b[3];
        if (s.within_bound() && s.best.sel.sum_sq > kSecondStartSumSq && two_cluster_endpoints(rgb, proj, a, b)) {
            s.try_both(pack(quantize(a)), pack(quantize(b)));
            s.fit_squared_error(3);
            s.refine(2);
            s.fit_squared_error(3);
        }
    }
    const bool missed = !s.best.valid || (options.max_error >= 0 && s.best.sel.max_err > options.max_error);
    if (options.quality == Quality::Best || missed) {
        // More starts: the other box diagonals, inset principal endpoints, then long refinement.
        for (int corner = 1; corner < 4; ++corner) {
            uint16_t pa, pb;
            box_corner(corner, pa, pb);
            s.try_both(pa, pb);
        }
        for (double f : {0.0625, 0.125, 0.25}) {
            uint16_t pa, pb;
            inset(f, pa, pb);
            s.try_both(pa, pb);
        }
        s.refine(32);
        s.fit_squared_error(8);
    }
    if (!s.best.valid) {
        // One-sided with no feasible candidate: all-black (0 is below any source >= 0).
        uint8_t idx[16];
        std::memset(idx, 3, sizeof idx);
        detail::write_bc1_block(0, 0, idx, out);
        detail::Palette<3> p;
        detail::bc1_interval_palette(0, 0, options.decoders, p);
        detail::Selection sel = detail::select_indices(p, rgb, options.one_sided_below);
        if (std::isfinite(sel.max_err)) {
            detail::write_bc1_block(0, 0, sel.idx, out);
            return {sel.max_err, sel.sum_sq, true};
        }
        detail::Selection any = detail::select_indices(p, rgb, false);
        return {any.max_err, any.sum_sq, false};
    }
    detail::write_bc1_block(s.best.c0, s.best.c1, s.best.sel.idx, out);
    return {s.best.sel.max_err, s.best.sel.sum_sq, true};
}
} // namespace

} // namespace atlas::compress

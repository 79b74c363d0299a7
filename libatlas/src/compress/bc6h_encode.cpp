// BC6H encoder: candidate (mode, partition) choice per quality, principal-axis
// endpoints, palette-optimal index selection, +-1 endpoint refinement. Every
// candidate is scored with the decoder's own integer steps (bc6h_internal.h), so
// the scores are the errors of the written block.
#include "atlas/compress/bc6h.h"
#include "atlas/core/error.h"

#include "bc6h_internal.h"
#include "half.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>

namespace atlas::compress {

namespace {

using namespace detail::bc6h;

constexpr float kHalfMax = 65504.0f;

// Exact half -> float without ldexp (hot loop).
inline float half_bits_to_float(uint16_t h) {
    const uint32_t s = uint32_t(h & 0x8000) << 16;
    const uint32_t e = (h >> 10) & 31, m = h & 1023u;
    float f;
    if (e == 0) {
        f = float(m) * (1.0f / 16777216.0f);
        return s ? -f : f;
    }
    const uint32_t bits = e == 31 ? (s | 0x7f800000u | (m << 13)) : (s | ((e + 112) << 23) | (m << 13));
    std::memcpy(&f, &bits, 4);
    return f;
}

struct Block {
    bool sg = false;
    float src[48];     // as given (errors are measured against these)
    float clamped[48]; // inside the representable range
    float q[16][3];    // target in the 16-bit interpolation domain (centre of the finish interval)
};

struct Score {
    float max_err = INFINITY;
    double sum_sq = INFINITY;
    bool operator<(const Score& o) const { return max_err < o.max_err || (max_err == o.max_err && sum_sq < o.sum_sq); }
};

struct Candidate {
    Logical L;
    Score s;
};

// The target of one value: the middle of the interpolation values that finish to its half.
float target_q(float v, bool sg) {
    const uint16_t h = detail::float_to_half(v);
    const int mag = h & 0x7FFF;
    if (!sg) return float((double(mag) + 0.5) * 64.0 / 31.0);
    if (mag == 0) return 0.0f;
    const float a = float((double(mag) + 0.5) * 32.0 / 31.0);
    return (h & 0x8000) ? -a : a;
}

// The endpoint code whose unquantized value is closest to q.
int quantize(float q, int w, bool sg) {
    const int lo = sg ? -((1 << (w - 1)) - 1) : 0, hi = sg ? (1 << (w - 1)) - 1 : (1 << w) - 1;
    const float scale = sg ? float(1 << (w - 1)) / 32768.0f : float(1 << w) / 65536.0f;
    const int guess = int(std::floor(q * scale - 0.5f));
    int best = std::clamp(guess, lo, hi);
    float best_d = std::fabs(float(unquantize(best, w, sg)) - q);
    for (int e = guess - 1; e <= guess + 2; ++e) {
        const int c = std::clamp(e, lo, hi);
        const float d = std::fabs(float(unquantize(c, w, sg)) - q);
        if (d < best_d) { best_d = d; best = c; }
    }
    return best;
}

// Moves endpoints 1..3 so that their deltas fit the mode (toward endpoint 0).
void clamp_to_mode(int m, int e[4][3]) {
    const ModeInfo& mi = kModes[m];
    if (!mi.transformed) return;
    for (int k = 1; k < 2 * mi.regions; ++k)
        for (int c = 0; c < 3; ++c) {
            const int r = 1 << (mi.d[c] - 1);
            e[k][c] = std::clamp(e[k][c], e[0][c] - r, e[0][c] + r - 1);
        }
}

// Optimal indices for the palette of L's endpoints (per texel: min max-channel error,
// then min squared error; anchors restricted to indices with the top bit clear).
Score choose_indices(const Block& b, Logical& L) {
    const ModeInfo& mi = kModes[L.mode];
    const int n = mi.regions == 2 ? 8 : 16;
    const int* wts = mi.regions == 2 ? kWeights3 : kWeights4;
    float pal[2][16][3];
    for (int r = 0; r < mi.regions; ++r)
        for (int c = 0; c < 3; ++c) {
            const int u0 = unquantize(L.e[2 * r][c], mi.w, b.sg), u1 = unquantize(L.e[2 * r + 1][c], mi.w, b.sg);
            for (int i = 0; i < n; ++i) pal[r][i][c] = half_bits_to_float(finish(interpolate(u0, u1, wts[i]), b.sg));
        }
    Score s;
    s.max_err = 0;
    s.sum_sq = 0;
    for (int t = 0; t < 16; ++t) {
        const int r = region_of(L.partition, mi.regions, t);
        const int limit = is_anchor(L.partition, mi.regions, t) ? n / 2 : n;
        const float* x = b.src + 3 * t;
        float best_m = INFINITY, best_q = INFINITY;
        int best_i = 0;
        for (int i = 0; i < limit; ++i) {
            const float d0 = pal[r][i][0] - x[0], d1 = pal[r][i][1] - x[1], d2 = pal[r][i][2] - x[2];
            const float m = std::max({std::fabs(d0), std::fabs(d1), std::fabs(d2)});
            const float q = d0 * d0 + d1 * d1 + d2 * d2;
            if (m < best_m || (m == best_m && q < best_q)) { best_m = m; best_q = q; best_i = i; }
        }
        L.idx[t] = uint8_t(best_i);
        s.max_err = std::max(s.max_err, best_m);
        s.sum_sq += double(best_q);
    }
    return s;
}

// Principal-axis extremes of the texels of one region (q domain): lo and hi endpoints.
void region_extremes(const Block& b, uint16_t mask, float lo[3], float hi[3]) {
    float mean[3] = {0, 0, 0};
    int n = 0;
    for (int t = 0; t < 16; ++t)
        if (mask >> t & 1) { for (int c = 0; c < 3; ++c) mean[c] += b.q[t][c]; ++n; }
    for (int c = 0; c < 3; ++c) mean[c] /= float(n);
    float cov[6] = {0, 0, 0, 0, 0, 0}; // xx xy xz yy yz zz
    for (int t = 0; t < 16; ++t)
        if (mask >> t & 1) {
            const float d[3] = {b.q[t][0] - mean[0], b.q[t][1] - mean[1], b.q[t][2] - mean[2]};
            cov[0] += d[0] * d[0]; cov[1] += d[0] * d[1]; cov[2] += d[0] * d[2];
            cov[3] += d[1] * d[1]; cov[4] += d[1] * d[2]; cov[5] += d[2] * d[2];
        }
    // Power iteration from the largest diagonal axis.
    float ax[3] = {0, 0, 0};
    ax[cov[0] >= cov[3] && cov[0] >= cov[5] ? 0 : cov[3] >= cov[5] ? 1 : 2] = 1;
    for (int it = 0; it < 8; ++it) {
        const float v[3] = {cov[0] * ax[0] + cov[1] * ax[1] + cov[2] * ax[2], cov[1] * ax[0] + cov[3] * ax[1] + cov[4] * ax[2],
                            cov[2] * ax[0] + cov[4] * ax[1] + cov[5] * ax[2]};
        const float len = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        if (!(len > 0)) break;
        for (int c = 0; c < 3; ++c) ax[c] = v[c] / len;
    }
    float pmin = INFINITY, pmax = -INFINITY;
    for (int t = 0; t < 16; ++t)
        if (mask >> t & 1) {
            const float p = (b.q[t][0] - mean[0]) * ax[0] + (b.q[t][1] - mean[1]) * ax[1] + (b.q[t][2] - mean[2]) * ax[2];
            pmin = std::min(pmin, p);
            pmax = std::max(pmax, p);
        }
    for (int c = 0; c < 3; ++c) {
        lo[c] = mean[c] + pmin * ax[c];
        hi[c] = mean[c] + pmax * ax[c];
    }
}

// Moments of a set of texels (q domain), in double: q^2 sums reach 7e10.
struct Moments {
    double n = 0, s[3] = {0, 0, 0}, ss[6] = {0, 0, 0, 0, 0, 0}; // xx xy xz yy yz zz
};

// Sum of squared distances of the texels to their principal line: trace(C) - lambda_max(C).
double line_residual(const Moments& m) {
    if (m.n < 2) return 0;
    const double c[6] = {m.ss[0] - m.s[0] * m.s[0] / m.n, m.ss[1] - m.s[0] * m.s[1] / m.n, m.ss[2] - m.s[0] * m.s[2] / m.n,
                         m.ss[3] - m.s[1] * m.s[1] / m.n, m.ss[4] - m.s[1] * m.s[2] / m.n, m.ss[5] - m.s[2] * m.s[2] / m.n};
    const double trace = c[0] + c[3] + c[5];
    double v[3] = {0, 0, 0};
    v[c[0] >= c[3] && c[0] >= c[5] ? 0 : c[3] >= c[5] ? 1 : 2] = 1;
    double lambda = 0;
    for (int it = 0; it < 6; ++it) {
        const double w[3] = {c[0] * v[0] + c[1] * v[1] + c[2] * v[2], c[1] * v[0] + c[3] * v[1] + c[4] * v[2],
                             c[2] * v[0] + c[4] * v[1] + c[5] * v[2]};
        const double len = std::sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
        if (!(len > 0)) break;
        lambda = len; // |C v| with |v| = 1 converges to lambda_max
        for (int k = 0; k < 3; ++k) v[k] = w[k] / len;
    }
    return std::max(0.0, trace - lambda);
}

// The residual of every two-region partition, from per-texel moments.
void partition_residuals(const Block& b, double res[32]) {
    double p[16][9];
    Moments all;
    for (int t = 0; t < 16; ++t) {
        const double x = b.q[t][0], y = b.q[t][1], z = b.q[t][2];
        const double v[9] = {x, y, z, x * x, x * y, x * z, y * y, y * z, z * z};
        for (int k = 0; k < 9; ++k) p[t][k] = v[k];
        all.n += 1;
        for (int k = 0; k < 3; ++k) all.s[k] += v[k];
        for (int k = 0; k < 6; ++k) all.ss[k] += v[3 + k];
    }
    for (int part = 0; part < 32; ++part) {
        Moments r1;
        for (int t = 0; t < 16; ++t)
            if (kPartitions[part] >> t & 1) {
                r1.n += 1;
                for (int k = 0; k < 3; ++k) r1.s[k] += p[t][k];
                for (int k = 0; k < 6; ++k) r1.ss[k] += p[t][3 + k];
            }
        Moments r0;
        r0.n = all.n - r1.n;
        for (int k = 0; k < 3; ++k) r0.s[k] = all.s[k] - r1.s[k];
        for (int k = 0; k < 6; ++k) r0.ss[k] = all.ss[k] - r1.ss[k];
        res[part] = line_residual(r0) + line_residual(r1);
    }
}

// Real-valued endpoints (q domain) of a (partition, regions) choice, ordered so that each
// region's anchor texel lies nearer its first endpoint.
struct RealEnds {
    float e[4][3];
};
RealEnds real_endpoints(const Block& b, int regions, int p) {
    RealEnds R{};
    for (int r = 0; r < regions; ++r) {
        const uint16_t mask = regions == 1 ? uint16_t(0xFFFF) : r ? kPartitions[p] : uint16_t(~kPartitions[p]);
        float lo[3], hi[3];
        region_extremes(b, mask, lo, hi);
        const int anchor = r == 0 ? 0 : kAnchor2[p];
        float dl = 0, dh = 0;
        for (int c = 0; c < 3; ++c) {
            dl += (b.q[anchor][c] - lo[c]) * (b.q[anchor][c] - lo[c]);
            dh += (b.q[anchor][c] - hi[c]) * (b.q[anchor][c] - hi[c]);
        }
        const bool swap = dh < dl;
        for (int c = 0; c < 3; ++c) {
            R.e[2 * r][c] = swap ? hi[c] : lo[c];
            R.e[2 * r + 1][c] = swap ? lo[c] : hi[c];
        }
    }
    return R;
}

// Quantizes real endpoints for mode m; false when the deltas do not fit the mode.
bool quantize_candidate(const Block& b, const RealEnds& R, int m, int p, Candidate& out) {
    const ModeInfo& mi = kModes[m];
    out.L = Logical{};
    out.L.mode = m;
    out.L.partition = mi.regions == 2 ? p : 0;
    for (int k = 0; k < 2 * mi.regions; ++k)
        for (int c = 0; c < 3; ++c) out.L.e[k][c] = quantize(R.e[k][c], mi.w, b.sg);
    return fits(m, out.L.e, b.sg);
}

// Quantizes, clamps the deltas if needed (the candidate stays valid) and scores.
bool make_candidate(const Block& b, const RealEnds& R, int m, int p, Candidate& out) {
    const bool exact = quantize_candidate(b, R, m, p, out);
    if (!exact) clamp_to_mode(m, out.L.e);
    out.s = choose_indices(b, out.L);
    return exact;
}

// Rounds of +-1 moves of every endpoint channel, keeping improvements that fit the mode.
void refine(const Block& b, Candidate& cand, int rounds) {
    const ModeInfo& mi = kModes[cand.L.mode];
    for (int round = 0; round < rounds; ++round) {
        bool improved = false;
        for (int k = 0; k < 2 * mi.regions; ++k)
            for (int c = 0; c < 3; ++c)
                for (int step : {-1, 1}) {
                    Candidate t = cand;
                    t.L.e[k][c] += step;
                    if (!fits(t.L.mode, t.L.e, b.sg)) continue;
                    t.s = choose_indices(b, t.L);
                    if (t.s < cand.s) { cand = t; improved = true; }
                }
        if (!improved) break;
    }
}

// Two-region modes from the most to the least precise endpoints.
constexpr int kTwoRegionOrder[10] = {2, 3, 4, 0, 5, 6, 7, 8, 1, 9};

void consider(Candidate& best, const Candidate& c) {
    if (c.s < best.s) best = c;
}

Candidate search(const Block& b, Quality q) {
    Candidate best;
    // Best starts from Normal's answer, so it is never worse than Normal (nor Normal than Fast).
    if (q == Quality::Best) best = search(b, Quality::Normal);
    // One region: 10-bit direct always fits; the most precise delta mode that fits.
    const RealEnds one = real_endpoints(b, 1, 0);
    Candidate c;
    make_candidate(b, one, 10, 0, c);
    consider(best, c);
    for (int m : {13, 12, 11}) {
        if (q == Quality::Best) {
            make_candidate(b, one, m, 0, c);
            consider(best, c);
        } else if (quantize_candidate(b, one, m, 0, c)) {
            c.s = choose_indices(b, c.L);
            consider(best, c);
            break;
        }
    }
    if (q == Quality::Fast) return best;

    // Two regions: partitions ranked by the principal-line residual.
    int order[32];
    double res[32];
    partition_residuals(b, res);
    for (int p = 0; p < 32; ++p) order[p] = p;
    std::stable_sort(order, order + 32, [&](int x, int y) { return res[x] < res[y]; });
    const int tries = q == Quality::Best ? 32 : 4;
    Candidate top[3];
    for (int i = 0; i < tries; ++i) {
        const int p = order[i];
        const RealEnds two = real_endpoints(b, 2, p);
        if (q == Quality::Best) {
            for (int m : kTwoRegionOrder) {
                make_candidate(b, two, m, p, c);
                consider(best, c);
                for (Candidate& t : top)
                    if (c.s < t.s) std::swap(t, c); // keeps the 3 best, sorted
            }
            continue;
        }
        // Normal: the most precise mode whose deltas fit, and the direct 6-bit mode.
        for (int m : kTwoRegionOrder) {
            if (m == 9 || !quantize_candidate(b, two, m, p, c)) continue;
            c.s = choose_indices(b, c.L);
            consider(best, c);
            break;
        }
        make_candidate(b, two, 9, p, c);
        consider(best, c);
    }
    if (q == Quality::Best) {
        refine(b, best, 16);
        for (Candidate& t : top)
            if (std::isfinite(t.s.max_err)) { refine(b, t, 16); consider(best, t); }
    } else {
        refine(b, best, 1);
    }
    return best;
}

// The last flat block (16 texels with the same bits) this thread encoded, with its
// signedness, options and result. The modeling NVDF's empty space is runs of one
// (profile, detail type, density scale): 57% of the cloudscape's blocks repeat the flat
// block before them. The encode is a pure function of block, signedness and options,
// so a repeat answered from here has the same bytes on any thread and in any order.
struct FlatMemo {
    bool valid = false;
    uint32_t colour[3];
    bool is_signed;
    BlockOptions options;
    uint8_t out[16];
    BlockResult result;
};
thread_local FlatMemo flat_memo;

BlockResult encode_block(const float rgb[48], bool is_signed, const BlockOptions& options, uint8_t out[16]);

} // namespace

BlockResult encode_bc6h_block(const float rgb[48], bool is_signed, const BlockOptions& options, uint8_t out[16]) {
    uint32_t bits[48];
    std::memcpy(bits, rgb, sizeof bits);
    bool flat = true;
    for (int t = 1; t < 16 && flat; ++t) flat = bits[3 * t] == bits[0] && bits[3 * t + 1] == bits[1] && bits[3 * t + 2] == bits[2];
    if (!flat) return encode_block(rgb, is_signed, options, out);
    FlatMemo& m = flat_memo;
    if (m.valid && std::memcmp(m.colour, bits, sizeof m.colour) == 0 && m.is_signed == is_signed && m.options == options) {
        std::memcpy(out, m.out, 16);
        return m.result;
    }
    const BlockResult r = encode_block(rgb, is_signed, options, out); // throws on NaN: nothing remembered
    m.valid = true;
    std::memcpy(m.colour, bits, sizeof m.colour);
    m.is_signed = is_signed;
    m.options = options;
    std::memcpy(m.out, out, 16);
    m.result = r;
    return r;
}

namespace {
BlockResult encode_block(const float rgb[48], bool is_signed, const BlockOptions& options, uint8_t out[16]) {
    Block b;
    b.sg = is_signed;
    const float lo = is_signed ? -kHalfMax : 0.0f;
    for (int i = 0; i < 48; ++i) {
        if (!std::isfinite(rgb[i]))
            throw Error("bc6h: texel " + std::to_string(i / 3) + " channel " + std::to_string(i % 3) + " of the block is " +
                        (std::isnan(rgb[i]) ? "NaN" : "infinite"));
        b.src[i] = rgb[i];
        b.clamped[i] = std::clamp(rgb[i], lo, kHalfMax);
        b.q[i / 3][i % 3] = target_q(b.clamped[i], is_signed);
    }
    Candidate best = search(b, options.quality);
    if (options.max_error >= 0 && best.s.max_err > options.max_error && options.quality != Quality::Best) {
        const Candidate wide = search(b, Quality::Best);
        if (wide.s < best.s) best = wide;
    }
    pack(best.L, is_signed, out);
    // The result is measured on the written bytes.
    float dec[48];
    decode_bc6h_block(out, is_signed, dec);
    BlockResult r;
    for (int i = 0; i < 48; ++i) {
        const double d = double(dec[i]) - double(rgb[i]);
        r.max_error = std::max(r.max_error, float(std::fabs(d)));
        r.sum_sq += d * d;
    }
    return r;
}
} // namespace

} // namespace atlas::compress

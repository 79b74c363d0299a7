// bc1-scalar, one-sided, on blocks of real signed distance fields: the encoder's max
// error against an exhaustive endpoint search written here (independent of the
// encoder's candidates), under the same decoder set.
//
// The blocks are 4x4 samples of the exact distance to a union of spheres and a box
// (cloud-sized shapes in a 4 km x 4 km x 512 m world), at several voxel sizes, mapped
// with the range -256..4096 m that graphs/cloudscape.yaml uses for its field data.
#include "atlas/compress/bc1.h"
#include "atlas/compress/bc1_scalar.h"
#include "test_blocks.h"

#include <gtest/gtest.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

namespace atlas::compress {
namespace {

using test::unit;

constexpr float kLo = -256.0f, kHi = 4096.0f;

#if defined(ATLAS_SANITIZED) || !defined(NDEBUG)
constexpr int kSdfBlocks = 600; // sanitizer / Debug builds: the exhaustive search is ~20x slower
#else
constexpr int kSdfBlocks = 10000;
#endif

// Exact distance (m) to the union of a few spheres and a box; negative inside.
double scene_distance(int scene, double x, double y, double z) {
    double d = 1e30;
    for (int i = 0; i < 6; ++i) {
        const double cx = 400 + 3300 * unit(100 + scene, uint64_t(4 * i)), cy = 400 + 3300 * unit(100 + scene, uint64_t(4 * i + 1));
        const double cz = 120 + 260 * unit(100 + scene, uint64_t(4 * i + 2)), r = 60 + 180 * unit(100 + scene, uint64_t(4 * i + 3));
        d = std::min(d, std::sqrt((x - cx) * (x - cx) + (y - cy) * (y - cy) + (z - cz) * (z - cz)) - r);
    }
    // An axis-aligned box (exact distance inside and outside).
    const double bx = 2000, by = 2100, bz = 250, hx = 300, hy = 180, hz = 120;
    const double qx = std::fabs(x - bx) - hx, qy = std::fabs(y - by) - hy, qz = std::fabs(z - bz) - hz;
    const double out = std::sqrt(std::max(qx, 0.0) * std::max(qx, 0.0) + std::max(qy, 0.0) * std::max(qy, 0.0) +
                                 std::max(qz, 0.0) * std::max(qz, 0.0));
    return std::min(d, out + std::min(std::max({qx, qy, qz}), 0.0));
}

// Block k: a 4x4 patch in a random plane orientation at one of several voxel sizes,
// half of them near a surface; normalized as the texture code maps values.
void sdf_block(uint64_t k, float out[16]) {
    constexpr double kVoxel[5] = {2, 4, 8, 16, 32};
    const double voxel = kVoxel[k % 5];
    const int scene = int((k / 5) % 4);
    double x = 4096 * unit(k, 1), y = 4096 * unit(k, 2), z = 512 * unit(k, 3);
    if (k % 2 == 0) { // near a surface: walk towards it along the distance
        for (int it = 0; it < 8; ++it) {
            const double d = scene_distance(scene, x, y, z), e = 0.5;
            const double gx = scene_distance(scene, x + e, y, z) - scene_distance(scene, x - e, y, z);
            const double gy = scene_distance(scene, x, y + e, z) - scene_distance(scene, x, y - e, z);
            const double gz = scene_distance(scene, x, y, z + e) - scene_distance(scene, x, y, z - e);
            const double g = std::max(1e-9, std::sqrt(gx * gx + gy * gy + gz * gz));
            const double target = 200 * (unit(k, 4) - 0.3);
            x -= (d - target) * gx / g;
            y -= (d - target) * gy / g;
            z -= (d - target) * gz / g;
        }
    }
    const int plane = int(unit(k, 5) * 3); // xy, xz or yz slice
    for (int t = 0; t < 16; ++t) {
        const double a = voxel * (t % 4), b = voxel * (t / 4);
        const double px = x + (plane == 2 ? 0 : a), py = y + (plane == 0 ? b : plane == 2 ? a : 0), pz = z + (plane == 0 ? 0 : b);
        const float v = float(std::clamp(scene_distance(scene, px, py, pz), double(kLo), double(kHi)));
        out[t] = std::clamp((v - kLo) / (kHi - kLo), 0.0f, 1.0f); // the texture code's to_norm
    }
}

// Channel palettes of every model, read back through the public BC1 decoder: blocks
// whose only varying channel is the one tabulated, in the mode asked for.
struct ChannelPalettes {
    // [four][a][b][entry]; for 5-bit channels only a, b < 32 are used.
    float r[2][32][32][4], g[2][64][64][4], b[2][32][32][4];
};

void read_palette(uint16_t c0, uint16_t c1, Decoder d, int channel, float out[4]) {
    uint8_t blk[8] = {uint8_t(c0), uint8_t(c0 >> 8), uint8_t(c1), uint8_t(c1 >> 8), 0xE4, 0xE4, 0xE4, 0xE4};
    float rgb[48];
    decode_bc1_block(blk, d, rgb);
    for (int i = 0; i < 4; ++i) out[i] = rgb[3 * i + channel];
}

ChannelPalettes channel_palettes(Decoder d) {
    ChannelPalettes P{};
    for (int a = 0; a < 32; ++a)
        for (int b = 0; b < 32; ++b) {
            if (a >= b) read_palette(uint16_t((a << 11) | 0x7FF), uint16_t(b << 11), d, 0, P.r[1][a][b]); // four colours
            if (a <= b) read_palette(uint16_t(a << 11), uint16_t((b << 11) | 0x7FF), d, 0, P.r[0][a][b]); // three colours
            read_palette(uint16_t((1 << 11) | a), uint16_t(b), d, 2, P.b[1][a][b]);
            read_palette(uint16_t(a), uint16_t((1 << 11) | b), d, 2, P.b[0][a][b]);
        }
    for (int a = 0; a < 64; ++a)
        for (int b = 0; b < 64; ++b) {
            read_palette(uint16_t((1 << 11) | (a << 5)), uint16_t(b << 5), d, 1, P.g[1][a][b]);
            read_palette(uint16_t(a << 5), uint16_t((1 << 11) | (b << 5)), d, 1, P.g[0][a][b]);
        }
    return P;
}

// The exhaustive one-sided search for one decoder set.
class ExhaustiveSearch {
public:
    explicit ExhaustiveSearch(DecoderSet set) : unpack_(bc1_scalar_unpack(set)) {
        for (Decoder d : decoders_in(set)) models_.push_back(channel_palettes(d));
        if (!(set & kReferenceOnly)) throw std::logic_error("the search's windows need the reference decoder in the set");
        ref_ = &models_[0]; // decoders_in lists Reference first
        for (int c = 0; c < 65536; ++c) {
            float e[4];
            reference_palette(uint16_t(c), 0, e);
            value_[size_t(c)] = e[0];
            sorted_.push_back({e[0], uint16_t(c)});
        }
        std::sort(sorted_.begin(), sorted_.end());
    }
    const ScalarUnpack& unpack() const { return unpack_; }

    // The worst one-sided error of standing for one value by one endpoint code: the
    // decoders' largest disagreement on an endpoint plus the largest gap between the
    // endpoints' upper values (over [0, 1]). The format's resolution under the set.
    float endpoint_slack() const {
        std::vector<float> his;
        float width = 0;
        for (int c = 0; c < 65536; ++c) {
            float lo = INFINITY, hi = -INFINITY;
            for (const ChannelPalettes& m : models_) {
                float e[4];
                palette(m, uint16_t(c), uint16_t(c), 0, e);
                lo = std::min(lo, e[0]);
                hi = std::max(hi, e[0]);
            }
            width = std::max(width, hi - lo);
            if (hi <= 1.0f) his.push_back(hi);
        }
        std::sort(his.begin(), his.end());
        float gap = 1.0f - his.back();
        for (size_t i = 1; i < his.size(); ++i) gap = std::max(gap, his[i] - his[i - 1]);
        return width + gap;
    }

    // Max one-sided error of pair (c0, c1) with optimal indices under every model, or
    // +inf when it is not below `stop` (early exit).
    float pair_error(uint16_t c0, uint16_t c1, const float src[16], float stop) const {
        float lo[4], hi[4];
        const int f = c0 > c1 ? 1 : 0;
        for (int i = 0; i < 4; ++i) { lo[i] = INFINITY; hi[i] = -INFINITY; }
        for (const ChannelPalettes& m : models_) {
            float e[4];
            palette(m, c0, c1, f, e);
            for (int i = 0; i < 4; ++i) { lo[i] = std::min(lo[i], e[i]); hi[i] = std::max(hi[i], e[i]); }
        }
        // One-sided must hold in exact arithmetic (issue 14 item 4): the float palette
        // rounds 4 times (channel value, product, two sums; terms >= 0), so the exact
        // entry lies within 2^-21 relative of it, and only an entry whose float value is
        // below the source by that much is provably below it. Without this, pairs one
        // float ulp from the source count (block 9570: an optimum of 0.015 m whose entry
        // is 1.3 ulp below its texel, against the encoder's provable 0.038 m).
        constexpr float kExact = 1.0f / 2097152.0f;
        for (int i = 0; i < 4; ++i) { hi[i] += std::fabs(hi[i]) * kExact; lo[i] -= std::fabs(lo[i]) * kExact; }
        float worst = 0;
        for (int t = 0; t < 16; ++t) {
            float best = INFINITY;
            for (int i = 0; i < 4; ++i)
                if (hi[i] <= src[t]) best = std::min(best, src[t] - lo[i]);
            worst = std::max(worst, best);
            if (!(worst < stop)) return INFINITY;
        }
        return worst;
    }

    // The smallest one-sided max error over all 65536^2 ordered endpoint pairs that is
    // below `stop`, or +inf if no pair gets below `stop`. Pairs are skipped only when
    // a necessary condition fails (see the comments), so "+inf" proves that no pair
    // reaches an error < stop.
    float best_below(const float src[16], float stop, uint16_t* best0 = nullptr, uint16_t* best1 = nullptr) const {
        float best = INFINITY;
        auto take = [&](uint16_t a, uint16_t b) {
            const float e = pair_error(a, b, src, std::min(best, stop));
            if (e < best) {
                best = e;
                if (best0) { *best0 = a; *best1 = b; }
            }
        };
        // (0, 0) is the three-colour mode with every entry exactly 0 (error = max).
        take(0, 0);
        float smin = src[0], smax = src[0];
        for (int t = 1; t < 16; ++t) { smin = std::min(smin, src[t]); smax = std::max(smax, src[t]); }
        if (!(smax >= std::min(best, stop))) return best; // nothing can beat the all-black block
        // Every texel s served with error < tau uses an entry with hi <= s and
        // lo > s - tau; the reference decoder is in the set, so the entry's reference
        // value lies in (s - tau, s]. Reference entries are the endpoints' values u, v
        // and (2u+v)/3, (u+2v)/3 (four colours) or (u+v)/2 (three colours) up to float
        // rounding, which kEps (normalized, ~10x the worst rounding) covers.
        constexpr float kEps = 2e-6f;
        for (int four = 0; four < 2; ++four) {
            const float tau = std::min(best, stop);
            if (!(smax >= tau)) break;
            // Anchors: the largest texel, and the smallest one that needs a non-black entry.
            float slo = smax;
            for (int t = 0; t < 16; ++t)
                if (four || src[t] >= tau) slo = std::min(slo, src[t]);
            // Entries as linear forms a*u + b*v.
            const int n = four ? 4 : 3;
            const double fa[4] = {1, 0, four ? 2.0 / 3 : 0.5, 1.0 / 3}, fb[4] = {0, 1, four ? 1.0 / 3 : 0.5, 2.0 / 3};
            std::vector<std::pair<double, double>> uwin; // intervals of u = value(c0)
            bool all_u = false;
            const double A0 = double(smax) - tau - kEps, A1 = double(smax) + kEps, B0 = double(slo) - tau - kEps, B1 = double(slo) + kEps;
            for (int k = 0; k < n; ++k)
                for (int j = 0; j < n; ++j) {
                    if (k == j) { // one entry serves both anchors
                        if (A0 > B1) continue;
                        if (k == 0) uwin.push_back({std::max(A0, B0), std::min(A1, B1)});
                        else all_u = true;
                        continue;
                    }
                    // Solve fa[k] u + fb[k] v = A, fa[j] u + fb[j] v = B for u.
                    const double det = fa[k] * fb[j] - fb[k] * fa[j];
                    if (std::fabs(det) < 1e-12) continue; // parallel forms (none here)
                    const double ca = fb[j] / det, cb = -fb[k] / det; // u = ca A + cb B
                    const double lo = std::min(ca * A0, ca * A1) + std::min(cb * B0, cb * B1);
                    const double hi = std::max(ca * A0, ca * A1) + std::max(cb * B0, cb * B1);
                    uwin.push_back({lo - 1e-9, hi + 1e-9});
                }
            if (all_u) uwin.assign(1, {-1.0, 2.0});
            std::sort(uwin.begin(), uwin.end());
            double done_to = -1e9;
            for (auto [ulo, uhi] : uwin) {
                ulo = std::max(ulo, done_to);
                if (ulo > uhi) continue;
                done_to = std::nextafter(uhi, 1e9);
                auto it = std::lower_bound(sorted_.begin(), sorted_.end(), std::pair<float, uint16_t>{float(ulo) , 0});
                while (it != sorted_.begin() && double(std::prev(it)->first) >= ulo) --it;
                for (; it != sorted_.end() && double(it->first) <= uhi; ++it) {
                    if (double(it->first) < ulo) continue;
                    search_partner(it->second, four != 0, src, stop, best, take);
                }
            }
        }
        return best < stop ? best : INFINITY;
    }

private:
    // Scalar palette of (c0, c1) under one model, in the unpack dot product's order.
    void palette(const ChannelPalettes& m, uint16_t c0, uint16_t c1, int f, float e[4]) const {
        const int r0 = c0 >> 11, r1 = c1 >> 11, g0 = (c0 >> 5) & 63, g1 = (c1 >> 5) & 63, b0 = c0 & 31, b1 = c1 & 31;
        const auto& w = unpack_.weights;
        for (int i = 0; i < 4; ++i) e[i] = m.r[f][r0][r1][i] * w[0] + m.g[f][g0][g1][i] * w[1] + m.b[f][b0][b1][i] * w[2];
    }
    void reference_palette(uint16_t c, int f, float e[4]) const { palette(*ref_, c, c, f, e); }

    // Every partner c1 of c0 (mode `four`: c0 > c1, else c0 <= c1) whose value v keeps
    // every texel within reach of some entry (intervals of v, intersected over texels).
    template <class Take>
    void search_partner(uint16_t c0, bool four, const float src[16], float stop, const float& best, Take& take) const {
        constexpr double kEps = 2e-6;
        const double tau = std::min(best, stop);
        const double u = value_[c0];
        std::vector<std::pair<double, double>> allowed{{-1.0, 2.0}}, next, mine;
        for (int t = 0; t < 16 && !allowed.empty(); ++t) {
            const double s = src[t], a = s - tau - kEps, b = s + kEps;
            if (!four && s < tau) continue;        // the exact black entry serves it
            if (u >= a && u <= b) continue;        // the c0 endpoint serves it, any v
            mine.clear();
            mine.push_back({a, b});                // the c1 endpoint
            if (four) {
                mine.push_back({3 * a - 2 * u - kEps, 3 * b - 2 * u + kEps});         // (2u + v) / 3
                mine.push_back({(3 * a - u) / 2 - kEps, (3 * b - u) / 2 + kEps});     // (u + 2v) / 3
            } else {
                mine.push_back({2 * a - u - kEps, 2 * b - u + kEps});                 // (u + v) / 2
            }
            next.clear();
            for (auto [x0, x1] : allowed)
                for (auto [y0, y1] : mine) {
                    const double lo = std::max(x0, y0), hi = std::min(x1, y1);
                    if (lo <= hi) next.push_back({lo, hi});
                }
            std::sort(next.begin(), next.end());
            allowed.clear();
            for (auto iv : next) { // merge overlaps
                if (!allowed.empty() && iv.first <= allowed.back().second) allowed.back().second = std::max(allowed.back().second, iv.second);
                else allowed.push_back(iv);
            }
        }
        for (auto [vlo, vhi] : allowed) {
            auto it = std::lower_bound(sorted_.begin(), sorted_.end(), std::pair<float, uint16_t>{float(vlo), 0});
            while (it != sorted_.begin() && double(std::prev(it)->first) >= vlo) --it;
            for (; it != sorted_.end() && double(it->first) <= vhi; ++it) {
                const uint16_t c1 = it->second;
                if (four ? !(c0 > c1) : !(c0 <= c1)) continue;
                take(c0, c1);
            }
        }
    }

    ScalarUnpack unpack_;
    std::vector<ChannelPalettes> models_;
    const ChannelPalettes* ref_ = nullptr;
    std::vector<float> value_ = std::vector<float>(65536);
    std::vector<std::pair<float, uint16_t>> sorted_;
};

// The error of a written block measured through the public scalar decoder.
float measured_error(const uint8_t blk[8], const ScalarUnpack& u, const float src[16], bool& one_sided) {
    float worst = 0;
    one_sided = true;
    for (Decoder d : decoders_in(u.decoders)) {
        float dec[16];
        decode_bc1_scalar_block(blk, d, u, dec);
        for (int t = 0; t < 16; ++t) {
            if (dec[t] > src[t]) one_sided = false;
            worst = std::max(worst, std::fabs(dec[t] - src[t]));
        }
    }
    return worst;
}

// Every block's error against the exhaustive optimum (issue 14's criterion: at most
// twice it). `strict`: asserted on every block, the search with stop = err / 2 proving
// that no pair reaches half the encoder's error. Otherwise asserted with the set's
// endpoint slack added (err <= 2 opt + slack) and the strict misses counted and bounded
// by `max_strict_misses`. Blocks are checked in parallel (the search is read-only).
void check_sdf_blocks(DecoderSet set, Quality q, int count, bool strict, int max_strict_misses = 0) {
    if (const char* c = std::getenv("ATLAS_SDF_COUNT")) count = std::atoi(c); // diagnosis
    const ExhaustiveSearch search(set);
    const ScalarUnpack& u = search.unpack();
    const float slack = strict ? 0.0f : search.endpoint_slack();
    BlockOptions o;
    o.one_sided_below = true;
    o.decoders = set;
    o.quality = q;
    struct Outcome {
        float err = 0, better = INFINITY;
        uint16_t c0 = 0, c1 = 0, e0 = 0, e1 = 0;
        float spread = 0, slack_better = INFINITY;
        bool one_sided = false, bound_ok = false;
    };
    std::vector<Outcome> out(static_cast<size_t>(count));
    std::vector<char> only;
    if (const char* list = std::getenv("ATLAS_SDF_ONLY")) { // diagnosis: check only these block numbers
        only.assign(size_t(count), 0);
        for (const char* p = list; *p;) {
            char* end;
            const long b = std::strtol(p, &end, 10);
            if (end == p) break;
            if (b >= 0 && b < count) only[size_t(b)] = 1;
            p = *end ? end + 1 : end;
        }
    }
    tbb::parallel_for(0, count, [&](int k) {
        if (!only.empty() && !only[size_t(k)]) return;
        float src[16];
        sdf_block(uint64_t(k), src);
        uint8_t blk[8];
        const BlockResult r = encode_bc1_scalar_block(src, u, o, blk);
        Outcome& oc = out[size_t(k)];
        oc.err = measured_error(blk, u, src, oc.one_sided);
        oc.e0 = uint16_t(blk[0] | (blk[1] << 8));
        oc.e1 = uint16_t(blk[2] | (blk[3] << 8));
        oc.spread = *std::max_element(src, src + 16) - *std::min_element(src, src + 16);
        oc.one_sided = oc.one_sided && r.one_sided_ok;
        oc.bound_ok = oc.err <= r.max_error;
        oc.better = search.best_below(src, 0.5f * oc.err, &oc.c0, &oc.c1);
        if (!strict && oc.better < INFINITY) oc.slack_better = search.best_below(src, 0.5f * (oc.err - slack));
    });
    int worse = 0, strict_misses = 0;
    double sum_err = 0, worst_err = 0, worst_ratio = 0;
    for (int k = 0; k < count; ++k) {
        if (!only.empty() && !only[size_t(k)]) continue;
        const Outcome& oc = out[size_t(k)];
        ASSERT_TRUE(oc.one_sided) << "block " << k << " is not one-sided";
        ASSERT_TRUE(oc.bound_ok) << "block " << k << ": measured error above the reported one";
        sum_err += oc.err;
        worst_err = std::max(worst_err, double(oc.err));
        if (oc.better < INFINITY) {
            ++strict_misses;
            worst_ratio = std::max(worst_ratio, double(oc.err / oc.better));
        }
        const bool fails = strict ? oc.better < INFINITY : oc.slack_better < INFINITY;
        if (oc.better < INFINITY && std::getenv("ATLAS_SDF_MISSES"))
            std::printf("miss block %d spread %.3f m: encoder (%u, %u) %.3f m, pair (%u, %u) %.3f m\n", k, oc.spread * (kHi - kLo), oc.e0, oc.e1,
                        oc.err * (kHi - kLo), oc.c0, oc.c1, oc.better * (kHi - kLo));
        if (oc.better < INFINITY && std::getenv("ATLAS_SDF_MISSES")) {
            float src[16];
            sdf_block(uint64_t(k), src);
            std::sort(src, src + 16);
            for (float v : src) std::printf(" %.3f", v * (kHi - kLo) + kLo);
            std::printf("\n");
        }
        if (fails && ++worse <= 5)
            ADD_FAILURE() << "block " << k << " (spread " << oc.spread * (kHi - kLo) << " m): encoder pair (" << oc.e0 << ", " << oc.e1 << ") "
                          << oc.err * (kHi - kLo) << " m, pair (" << oc.c0 << ", " << oc.c1 << ") reaches " << oc.better * (kHi - kLo)
                          << " m, less than half" << (strict ? "" : " (after the endpoint slack)");
    }
    EXPECT_EQ(worse, 0) << "blocks above twice the exhaustive optimum" << (strict ? "" : " plus the endpoint slack");
    // The allowance is a fraction of the blocks, at least 2 (sanitizer builds check 600).
    EXPECT_LE(strict_misses, std::max(max_strict_misses, strict ? 0 : 2)) << "blocks above twice the exhaustive optimum";
    std::printf("bc1-scalar one-sided SDF blocks (%s, %d): max error %.2f m, mean %.2f m; %d above twice the exhaustive optimum "
                "(worst %.2fx; endpoint slack %.3f m)\n",
                quality_name(q), count, worst_err * (kHi - kLo), sum_err / count * (kHi - kLo), strict_misses, worst_ratio,
                search.endpoint_slack() * (kHi - kLo));
}

// The search itself: on random pairs' own palettes it finds an error no larger than
// the pair's (the pair is one of the candidates it must not skip).
TEST(Bc1ScalarSdf, ExhaustiveSearchNeverMissesAKnownPair) {
    const DecoderSet set = kReferenceOnly | decoder_bit(Decoder::Nvidia) | decoder_bit(Decoder::Amd);
    const ExhaustiveSearch search(set);
    for (int k = 0; k < kSdfBlocks / 250; ++k) {
        float src[16];
        sdf_block(uint64_t(k) * 7 + 3, src);
        // A random pair near the block: its own error is an upper bound of the optimum.
        uint8_t blk[8];
        BlockOptions o;
        o.one_sided_below = true;
        o.decoders = set;
        encode_bc1_scalar_block(src, search.unpack(), o, blk);
        const uint16_t c0 = uint16_t(blk[0] | (blk[1] << 8)), c1 = uint16_t(blk[2] | (blk[3] << 8));
        const float own = search.pair_error(c0, c1, src, INFINITY);
        const float found = search.best_below(src, std::nextafter(own, INFINITY));
        ASSERT_LE(found, own) << "block " << k;
        // Perturbed pairs too (not the encoder's choice).
        for (int j = 0; j < 2; ++j) {
            const uint16_t a = uint16_t(c0 + int(unit(k, 50 + j) * 40) - 20), b = uint16_t(c1 + int(unit(k, 60 + j) * 40) - 20);
            const float e = search.pair_error(a, b, src, INFINITY);
            if (!std::isfinite(e)) continue;
            ASSERT_LE(search.best_below(src, std::nextafter(e, INFINITY)), e) << "block " << k << " pair " << a << ", " << b;
        }
    }
}

// The decoder set graphs/cloudscape.yaml uses for its field data, at the default level:
// strictly within twice the exhaustive optimum on every block (issue 14's criterion;
// before the fit's endpoint-unused assignments, the shared-R bottom after the first
// pass and the wider single-entry gate, 10 of 10^4 blocks missed it, worst 2.71x).
TEST(Bc1ScalarSdf, NormalStrictlyWithinTwiceTheExhaustiveOptimumReferenceNvidiaAmd) {
    check_sdf_blocks(kReferenceOnly | decoder_bit(Decoder::Nvidia) | decoder_bit(Decoder::Amd), Quality::Normal, kSdfBlocks, true);
}

// Reference only: the slack is one 16-bit endpoint step (0.07 m here).
TEST(Bc1ScalarSdf, NormalWithinTwiceTheExhaustiveOptimumPlusSlackReferenceOnly) {
    check_sdf_blocks(kReferenceOnly, Quality::Normal, kSdfBlocks / 5, false, kSdfBlocks / 5 / 100);
}

// Best: strictly within twice the optimum on every block (issue 14's criterion).
TEST(Bc1ScalarSdf, BestStrictlyWithinTwiceTheExhaustiveOptimumReferenceNvidiaAmd) {
    check_sdf_blocks(kReferenceOnly | decoder_bit(Decoder::Nvidia) | decoder_bit(Decoder::Amd), Quality::Best, kSdfBlocks / 5, true);
}

// Reference only, Best: a few blocks whose errors are centimetres (a fraction of one
// 16-bit endpoint step) miss twice the optimum; the slack holds on every block.
TEST(Bc1ScalarSdf, BestWithinTwiceTheExhaustiveOptimumPlusSlackReferenceOnly) {
    check_sdf_blocks(kReferenceOnly, Quality::Best, kSdfBlocks / 5, false, kSdfBlocks / 5 / 200);
}

} // namespace
} // namespace atlas::compress

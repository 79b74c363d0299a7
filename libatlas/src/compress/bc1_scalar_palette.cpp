// bc1-scalar interval palettes from weighted channel tables (see bc1_scalar_palette.h).
#include "bc1_scalar_palette.h"

#include "bc1_palette.h"

#include <algorithm>
#include <array>
#include <limits>
#include <mutex>

#if defined(__SSE2__)
#include <xmmintrin.h>
#endif

namespace atlas::compress::detail {

float channel_level_value(int i, int bits, Decoder d) {
    const int m = (1 << bits) - 1;
    if (d == Decoder::Reference || d == Decoder::Conformant) return float(i) / float(m);
    const int e = bits == 5 ? ((i << 3) | (i >> 2)) : ((i << 2) | (i >> 4));
    return float(e) / 255.0f;
}

namespace {

float level_value(int i, int bits, Decoder d) { return channel_level_value(i, bits, d); }

std::unique_ptr<ScalarTables> build(const ScalarUnpack& u) {
    auto T = std::make_unique<ScalarTables>();
    T->unpack = u;
    const DecoderSet set = u.decoders == 0 ? kReferenceOnly : u.decoders;
    for (int i = 0; i < 32; ++i) T->ref5[i] = T->hi5[i] = level_value(i, 5, Decoder::Reference);
    for (int i = 0; i < 64; ++i) T->ref6[i] = T->hi6[i] = level_value(i, 6, Decoder::Reference);
    for (int di = 0; di < kDecoderCount; ++di) {
        if (!(set & (DecoderSet(1) << di))) continue;
        for (int i = 0; i < 32; ++i) T->hi5[i] = std::max(T->hi5[i], level_value(i, 5, Decoder(di)));
        for (int i = 0; i < 64; ++i) T->hi6[i] = std::max(T->hi6[i], level_value(i, 6, Decoder(di)));
    }
    T->conformant = (set & decoder_bit(Decoder::Conformant)) != 0;
    {
        float s5 = 0, s6 = 0;
        for (int i = 0; i < 32; ++i) {
            float lo = std::numeric_limits<float>::infinity(), hi = -std::numeric_limits<float>::infinity();
            for (int di = 0; di < kDecoderCount; ++di)
                if (set & (DecoderSet(1) << di)) { lo = std::min(lo, level_value(i, 5, Decoder(di))); hi = std::max(hi, level_value(i, 5, Decoder(di))); }
            s5 = std::max(s5, hi - lo);
        }
        for (int i = 0; i < 64; ++i) {
            float lo = std::numeric_limits<float>::infinity(), hi = -std::numeric_limits<float>::infinity();
            for (int di = 0; di < kDecoderCount; ++di)
                if (set & (DecoderSet(1) << di)) { lo = std::min(lo, level_value(i, 6, Decoder(di))); hi = std::max(hi, level_value(i, 6, Decoder(di))); }
            s6 = std::max(s6, hi - lo);
        }
        T->endpoint_slack = s5 * u.weights[0] + s6 * u.weights[1] + s5 * u.weights[2] + u.endpoint_step;
    }
    // Reference tables are always built (tie break); Conformant uses them too.
    const int conf = int(Decoder::Conformant);
    for (int di = 0; di < kDecoderCount; ++di) T->in_set[di] = di != conf && (set & (DecoderSet(1) << di));
    const float w0 = u.weights[0], w1 = u.weights[1], w2 = u.weights[2];
    for (int di = 0; di < kDecoderCount; ++di) {
        if (di == conf || !(di == 0 || T->in_set[di])) continue;
        for (int f = 0; f < 2; ++f) {
            for (int a = 0; a < 32; ++a)
                for (int b = 0; b < 32; ++b) {
                    const float* v = bc1_channel_palette(Decoder(di), f == 1, false, a, b);
                    for (int i = 0; i < 4; ++i) { T->r[di][f][a][b][i] = v[i] * w0; T->b[di][f][a][b][i] = v[i] * w2; }
                }
            for (int a = 0; a < 64; ++a)
                for (int b = 0; b < 64; ++b) {
                    const float* v = bc1_channel_palette(Decoder(di), f == 1, true, a, b);
                    for (int i = 0; i < 4; ++i) T->g[di][f][a][b][i] = v[i] * w1;
                }
        }
    }
    for (int a = 0; a < 32; ++a)
        for (int b = 0; b < 32; ++b) {
            const float tol = bc1_conformant_tolerance(T->ref5[a], T->ref5[b]);
            T->tr[a][b] = w0 * tol;
            T->tb[a][b] = w2 * tol;
        }
    for (int a = 0; a < 64; ++a)
        for (int b = 0; b < 64; ++b) T->tg[a][b] = w1 * bc1_conformant_tolerance(T->ref6[a], T->ref6[b]);
    return T;
}

} // namespace

const ScalarTables& scalar_tables(const ScalarUnpack& u, std::unique_ptr<ScalarTables>& local) {
    constexpr int kSets = 1 << kDecoderCount;
    static std::array<std::once_flag, kSets> once;
    static std::array<std::unique_ptr<ScalarTables>, kSets> shared; // written once per set, then read-only
    const DecoderSet set = u.decoders & ((DecoderSet(1) << kDecoderCount) - 1);
    std::call_once(once[set], [&] { shared[set] = build(bc1_scalar_unpack(set)); });
    if (set == u.decoders && shared[set]->unpack.weights == u.weights) return *shared[set];
    local = build(u);
    return *local;
}

void scalar_interval_palette(const ScalarTables& T, uint16_t c0, uint16_t c1, Palette<1>& p) {
    p.n = 4;
    const int f = c0 > c1 ? 1 : 0;
    const int r0 = (c0 >> 11) & 31, r1 = (c1 >> 11) & 31, g0 = (c0 >> 5) & 63, g1 = (c1 >> 5) & 63, b0 = c0 & 31, b1 = c1 & 31;
    // Every set contributes at least one model (Reference for an empty set, or
    // Conformant), so starting from +-inf and merging unconditionally is exact.
    constexpr float inf = std::numeric_limits<float>::infinity();
#if defined(__SSE2__)
    auto value = [&](int di) {
        return _mm_add_ps(_mm_add_ps(_mm_loadu_ps(T.r[di][f][r0][r1]), _mm_loadu_ps(T.g[di][f][g0][g1])),
                          _mm_loadu_ps(T.b[di][f][b0][b1])); // the dot product's order
    };
    const __m128 ref = value(0);
    __m128 lo = _mm_set1_ps(inf), hi = _mm_set1_ps(-inf);
    for (int di = 0; di < kDecoderCount; ++di) {
        if (!T.in_set[di]) continue;
        const __m128 v = di == 0 ? ref : value(di);
        lo = _mm_min_ps(v, lo); // = std::min(lo, v), also for equal zeros
        hi = _mm_max_ps(v, hi);
    }
    if (T.conformant) {
        const float t = ((0.0f + T.tr[r0][r1]) + T.tg[g0][g1]) + T.tb[b0][b1];
        const __m128 tv = _mm_set_ps(f == 1 ? t : 0.0f, t, t, t); // the 3-colour mode's black is exact
        lo = _mm_min_ps(_mm_sub_ps(ref, tv), lo);
        hi = _mm_max_ps(_mm_add_ps(ref, tv), hi);
    }
    float rv[4], lv[4], hv[4];
    _mm_storeu_ps(rv, ref);
    _mm_storeu_ps(lv, lo);
    _mm_storeu_ps(hv, hi);
    for (int i = 0; i < 4; ++i) { p.ref[i][0] = rv[i]; p.lo[i][0] = widen_down(lv[i]); p.hi[i][0] = widen_up(hv[i]); }
#else
    float ref[4], lo[4], hi[4];
    for (int i = 0; i < 4; ++i) {
        ref[i] = (T.r[0][f][r0][r1][i] + T.g[0][f][g0][g1][i]) + T.b[0][f][b0][b1][i]; // the dot product's order
        lo[i] = inf;
        hi[i] = -inf;
    }
    for (int di = 0; di < kDecoderCount; ++di) {
        if (!T.in_set[di]) continue;
        for (int i = 0; i < 4; ++i) {
            const float v = (T.r[di][f][r0][r1][i] + T.g[di][f][g0][g1][i]) + T.b[di][f][b0][b1][i];
            lo[i] = std::min(lo[i], v);
            hi[i] = std::max(hi[i], v);
        }
    }
    if (T.conformant) {
        const float t = ((0.0f + T.tr[r0][r1]) + T.tg[g0][g1]) + T.tb[b0][b1];
        for (int i = 0; i < 4; ++i) {
            const float ti = (f == 1 || i != 3) ? t : 0.0f; // the 3-colour mode's black is exact
            lo[i] = std::min(lo[i], ref[i] - ti);
            hi[i] = std::max(hi[i], ref[i] + ti);
        }
    }
    for (int i = 0; i < 4; ++i) { p.ref[i][0] = ref[i]; p.lo[i][0] = widen_down(lo[i]); p.hi[i][0] = widen_up(hi[i]); }
#endif
}

} // namespace atlas::compress::detail

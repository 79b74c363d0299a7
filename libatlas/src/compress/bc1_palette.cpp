// BC1 palette decoding under each decoder model.
// Formulas: Reference = D3D float interpolation of c/31, c/63. Tool8 = squish /
// OpenImageIO 2.4 (8-bit expansion, truncating (2a+b)/3). Nvidia and Amd = the
// published models (as in rgbcx / Giesen, "GPU BCn decoding", 2021).
#include "atlas/compress/bc1.h"

#include "bc1_palette.h"

#include <algorithm>
#include <cstring>
#include <memory>

namespace atlas::compress {

namespace {

int expand5(int v) { return (v << 3) | (v >> 2); }
int expand6(int v) { return (v << 2) | (v >> 4); }

int nv_interp5(int a, int b) { return ((2 * a + b) * 22) / 8; }
int nv_interp6(int c0, int c1) { int g = c1 - c0; return (256 * c0 + g / 4 + 128 + g * 80) / 256; }
int nv_half5(int a, int b) { return ((a + b) * 33) / 8; }
int nv_half6(int c0, int c1) { int g = c1 - c0; return (256 * c0 + g / 4 + 128 + g * 128) / 256; }
int amd_interp(int c0, int c1) { return (c0 * 43 + c1 * 21 + 32) / 64; }
int amd_half(int c0, int c1) { return (c0 + c1 + 1) >> 1; }

} // namespace

namespace {

// Palette of one channel (a, b: 5- or 6-bit endpoint values) under one model.
void channel_palette(int a, int b, bool six, bool four, Decoder d, float out[4]) {
    if (d == Decoder::Reference || d == Decoder::Conformant) {
        const float m = six ? 63.0f : 31.0f;
        out[0] = float(a) / m;
        out[1] = float(b) / m;
        if (four) {
            out[2] = float(2 * a + b) / (3.0f * m);
            out[3] = float(a + 2 * b) / (3.0f * m);
        } else {
            out[2] = float(a + b) / (2.0f * m);
            out[3] = 0.0f;
        }
        return;
    }
    const int A = six ? expand6(a) : expand5(a), B = six ? expand6(b) : expand5(b);
    int v2 = 0, v3 = 0;
    switch (d) {
    case Decoder::Tool8:
        if (four) { v2 = (2 * A + B) / 3; v3 = (A + 2 * B) / 3; }
        else v2 = (A + B) / 2;
        break;
    case Decoder::Tool8Round:
        if (four) { v2 = (2 * A + B + 1) / 3; v3 = (A + 2 * B + 1) / 3; }
        else v2 = (A + B + 1) / 2;
        break;
    case Decoder::Nvidia:
        if (four) {
            v2 = six ? nv_interp6(A, B) : nv_interp5(a, b);
            v3 = six ? nv_interp6(B, A) : nv_interp5(b, a);
        } else v2 = six ? nv_half6(A, B) : nv_half5(a, b);
        break;
    case Decoder::Amd:
        if (four) { v2 = amd_interp(A, B); v3 = amd_interp(B, A); }
        else v2 = amd_half(A, B);
        break;
    default: break;
    }
    out[0] = float(A) / 255.0f;
    out[1] = float(B) / 255.0f;
    out[2] = float(v2) / 255.0f;
    out[3] = float(v3) / 255.0f;
}

// Every channel palette of every model, built once (immutable after its
// thread-safe initialisation): the encoders evaluate thousands of pairs per block.
struct ChannelTables {
    float t5[kDecoderCount][2][32][32][4];
    float t6[kDecoderCount][2][64][64][4];
};

const ChannelTables& channel_tables() {
    static const std::unique_ptr<ChannelTables> tables = [] {
        auto t = std::make_unique<ChannelTables>();
        for (int d = 0; d < kDecoderCount; ++d)
            for (int f = 0; f < 2; ++f) {
                for (int a = 0; a < 32; ++a)
                    for (int b = 0; b < 32; ++b) channel_palette(a, b, false, f == 1, Decoder(d), t->t5[d][f][a][b]);
                for (int a = 0; a < 64; ++a)
                    for (int b = 0; b < 64; ++b) channel_palette(a, b, true, f == 1, Decoder(d), t->t6[d][f][a][b]);
            }
        return t;
    }();
    return *tables;
}

} // namespace

void bc1_palette(uint16_t c0, uint16_t c1, Decoder d, float out[4][3]) {
    const bool four = c0 > c1;
    const int raw0[3] = {(c0 >> 11) & 31, (c0 >> 5) & 63, c0 & 31};
    const int raw1[3] = {(c1 >> 11) & 31, (c1 >> 5) & 63, c1 & 31};
    for (int ch = 0; ch < 3; ++ch) {
        float v[4];
        channel_palette(raw0[ch], raw1[ch], ch == 1, four, d, v);
        for (int i = 0; i < 4; ++i) out[i][ch] = v[i];
    }
}

namespace detail {
void bc1_palette_fast(uint16_t c0, uint16_t c1, Decoder d, float out[4][3]) {
    const ChannelTables& T = channel_tables();
    const int f = c0 > c1 ? 1 : 0, di = int(d);
    const float* r = T.t5[di][f][(c0 >> 11) & 31][(c1 >> 11) & 31];
    const float* g = T.t6[di][f][(c0 >> 5) & 63][(c1 >> 5) & 63];
    const float* b = T.t5[di][f][c0 & 31][c1 & 31];
    for (int i = 0; i < 4; ++i) { out[i][0] = r[i]; out[i][1] = g[i]; out[i][2] = b[i]; }
}
const float* bc1_channel_palette(Decoder d, bool four, bool six, int a, int b) {
    const ChannelTables& T = channel_tables();
    return six ? T.t6[int(d)][four ? 1 : 0][a][b] : T.t5[int(d)][four ? 1 : 0][a][b];
}
} // namespace detail

void decode_bc1_block(const uint8_t block[8], Decoder d, float rgb[48]) {
    const uint16_t c0 = uint16_t(block[0] | (block[1] << 8)), c1 = uint16_t(block[2] | (block[3] << 8));
    float pal[4][3];
    bc1_palette(c0, c1, d, pal);
    const uint32_t bits = uint32_t(block[4]) | (uint32_t(block[5]) << 8) | (uint32_t(block[6]) << 16) | (uint32_t(block[7]) << 24);
    for (int t = 0; t < 16; ++t) {
        const int i = int((bits >> (2 * t)) & 3);
        for (int c = 0; c < 3; ++c) rgb[3 * t + c] = pal[i][c];
    }
}

namespace detail {

void bc1_interval_palette(uint16_t c0, uint16_t c1, DecoderSet set, Palette<3>& p) {
    p.n = 4;
    float ref[4][3];
    bc1_palette_fast(c0, c1, Decoder::Reference, ref);
    bool any = false;
    auto merge = [&](int i, int c, float lo, float hi) {
        if (!any) { p.lo[i][c] = lo; p.hi[i][c] = hi; }
        else { p.lo[i][c] = std::min(p.lo[i][c], lo); p.hi[i][c] = std::max(p.hi[i][c], hi); }
    };
    for (int i = 0; i < 4; ++i)
        for (int c = 0; c < 3; ++c) { p.ref[i][c] = ref[i][c]; p.lo[i][c] = p.hi[i][c] = ref[i][c]; }
    const bool four = c0 > c1;
    const DecoderSet use = set == 0 ? kReferenceOnly : set;
    for (int di = 0; di < kDecoderCount; ++di) {
        if (!(use & (DecoderSet(1) << di))) continue; // no allocation in the hot loop
        const Decoder d = static_cast<Decoder>(di);
        float v[4][3];
        if (d == Decoder::Conformant) {
            for (int i = 0; i < 4; ++i)
                for (int c = 0; c < 3; ++c) {
                    const float t = (!four && i == 3) ? 0.0f : bc1_conformant_tolerance(ref[0][c], ref[1][c]); // black is exact
                    merge(i, c, ref[i][c] - t, ref[i][c] + t);
                }
            any = true;
            continue;
        }
        bc1_palette_fast(c0, c1, d, v);
        for (int i = 0; i < 4; ++i)
            for (int c = 0; c < 3; ++c) merge(i, c, v[i][c], v[i][c]);
        any = true;
    }
}

void bc1_interval_palette_cm(uint16_t c0, uint16_t c1, DecoderSet set, Bc1PaletteCm& p) {
    const ChannelTables& T = channel_tables();
    const int f = c0 > c1 ? 1 : 0;
    const bool four = f == 1;
    const DecoderSet use = set == 0 ? kReferenceOnly : set;
    const int a[3] = {(c0 >> 11) & 31, (c0 >> 5) & 63, c0 & 31}, b[3] = {(c1 >> 11) & 31, (c1 >> 5) & 63, c1 & 31};
    if (use == kReferenceOnly) { // one model: lo = hi = ref
        const int d = int(Decoder::Reference);
        const float* v[3] = {T.t5[d][f][a[0]][b[0]], T.t6[d][f][a[1]][b[1]], T.t5[d][f][a[2]][b[2]]};
        for (int ch = 0; ch < 3; ++ch) {
            std::memcpy(p.ref[ch], v[ch], sizeof p.ref[ch]);
            std::memcpy(p.lo[ch], v[ch], sizeof p.lo[ch]);
            std::memcpy(p.hi[ch], v[ch], sizeof p.hi[ch]);
        }
        return;
    }
    for (int ch = 0; ch < 3; ++ch) {
        auto table = [&](int d) { return ch == 1 ? T.t6[d][f][a[ch]][b[ch]] : T.t5[d][f][a[ch]][b[ch]]; };
        const float* ref = table(int(Decoder::Reference));
        float lo[4], hi[4];
        for (int i = 0; i < 4; ++i) { p.ref[ch][i] = ref[i]; lo[i] = hi[i] = ref[i]; }
        bool any = false;
        // bc1_interval_palette's merge, entry by entry: the first model sets the interval,
        // the others widen it (std::min / std::max in the same order).
        for (int di = 0; di < kDecoderCount; ++di) {
            if (!(use & (DecoderSet(1) << di))) continue;
            const Decoder d = static_cast<Decoder>(di);
            float vlo[4], vhi[4];
            if (d == Decoder::Conformant) {
                const float t = bc1_conformant_tolerance(ref[0], ref[1]);
                for (int i = 0; i < 4; ++i) {
                    const float ti = (!four && i == 3) ? 0.0f : t; // black is exact
                    vlo[i] = ref[i] - ti;
                    vhi[i] = ref[i] + ti;
                }
            } else {
                const float* v = table(di);
                for (int i = 0; i < 4; ++i) vlo[i] = vhi[i] = v[i];
            }
            for (int i = 0; i < 4; ++i) {
                if (!any) { lo[i] = vlo[i]; hi[i] = vhi[i]; }
                else { lo[i] = std::min(lo[i], vlo[i]); hi[i] = std::max(hi[i], vhi[i]); }
            }
            any = true;
        }
        for (int i = 0; i < 4; ++i) { p.lo[ch][i] = lo[i]; p.hi[ch][i] = hi[i]; }
    }
}

} // namespace detail
} // namespace atlas::compress

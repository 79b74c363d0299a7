// BC6H decoding per the D3D11 functional specification, and the bit layout shared
// with the encoder (pack / unpack of the logical block).
#include "atlas/compress/bc6h.h"

#include "bc6h_internal.h"
#include "half.h"

namespace atlas::compress {

namespace detail::bc6h {

const ModeInfo kModes[14] = {
    {0x00, 2, 2, 10, {5, 5, 5}, true},   // 1: 10.555
    {0x01, 2, 2, 7, {6, 6, 6}, true},    // 2: 7.666
    {0x02, 5, 2, 11, {5, 4, 4}, true},   // 3: 11.555 11.444 11.444
    {0x06, 5, 2, 11, {4, 5, 4}, true},   // 4
    {0x0A, 5, 2, 11, {4, 4, 5}, true},   // 5
    {0x0E, 5, 2, 9, {5, 5, 5}, true},    // 6: 9.555
    {0x12, 5, 2, 8, {6, 5, 5}, true},    // 7: 8.655
    {0x16, 5, 2, 8, {5, 6, 5}, true},    // 8
    {0x1A, 5, 2, 8, {5, 5, 6}, true},    // 9
    {0x1E, 5, 2, 6, {6, 6, 6}, false},   // 10: 6.6.6.6, direct
    {0x03, 5, 1, 10, {10, 10, 10}, false}, // 11: 10.10, direct
    {0x07, 5, 1, 11, {9, 9, 9}, true},   // 12: 11.9
    {0x0B, 5, 1, 12, {8, 8, 8}, true},   // 13: 12.8
    {0x0F, 5, 1, 16, {4, 4, 4}, true},   // 14: 16.4
};

const uint16_t kPartitions[32] = {
    0xCCCC, 0x8888, 0xEEEE, 0xECC8, 0xC880, 0xFEEC, 0xFEC8, 0xEC80, 0xC800, 0xFFEC, 0xFE80,
    0xE800, 0xFFE8, 0xFF00, 0xFFF0, 0xF000, 0xF710, 0x008E, 0x7100, 0x08CE, 0x008C, 0x7310,
    0x3100, 0x8CCE, 0x088C, 0x3110, 0x6666, 0x366C, 0x17E8, 0x0FF0, 0x718E, 0x399C,
};
const uint8_t kAnchor2[32] = {15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 15,
                              15, 2, 8, 2, 2, 8, 8, 15, 2, 8, 2, 2, 8, 8, 2, 2};
const int kWeights3[8] = {0, 9, 18, 27, 37, 46, 55, 64};
const int kWeights4[16] = {0, 4, 9, 13, 17, 21, 26, 30, 34, 38, 43, 47, 51, 55, 60, 64};

namespace {

// Endpoint fields: endpoint e (w, x, y, z = 0..3) channel c is field 3*e + c; D = shape.
enum Field : uint8_t { RW, GW, BW, RX, GX, BX, RY, GY, BY, RZ, GZ, BZ, D, END };

// A run of bits stored consecutively: field bits first..last (descending when last < first).
struct Run {
    uint8_t field, first, last;
};

// Storage order after the mode bits (D3D11 spec, "BC6H compressed endpoint format").
constexpr Run kLayout[14][28] = {
    {{GY, 4, 4}, {BY, 4, 4}, {BZ, 4, 4}, {RW, 0, 9}, {GW, 0, 9}, {BW, 0, 9}, {RX, 0, 4}, {GZ, 4, 4}, {GY, 0, 3},
     {GX, 0, 4}, {BZ, 0, 0}, {GZ, 0, 3}, {BX, 0, 4}, {BZ, 1, 1}, {BY, 0, 3}, {RY, 0, 4}, {BZ, 2, 2}, {RZ, 0, 4},
     {BZ, 3, 3}, {D, 0, 4}, {END, 0, 0}},
    {{GY, 5, 5}, {GZ, 4, 4}, {GZ, 5, 5}, {RW, 0, 6}, {BZ, 0, 0}, {BZ, 1, 1}, {BY, 4, 4}, {GW, 0, 6}, {BY, 5, 5},
     {BZ, 2, 2}, {GY, 4, 4}, {BW, 0, 6}, {BZ, 3, 3}, {BZ, 5, 5}, {BZ, 4, 4}, {RX, 0, 5}, {GY, 0, 3}, {GX, 0, 5},
     {GZ, 0, 3}, {BX, 0, 5}, {BY, 0, 3}, {RY, 0, 5}, {RZ, 0, 5}, {D, 0, 4}, {END, 0, 0}},
    {{RW, 0, 9}, {GW, 0, 9}, {BW, 0, 9}, {RX, 0, 4}, {RW, 10, 10}, {GY, 0, 3}, {GX, 0, 3}, {GW, 10, 10}, {BZ, 0, 0},
     {GZ, 0, 3}, {BX, 0, 3}, {BW, 10, 10}, {BZ, 1, 1}, {BY, 0, 3}, {RY, 0, 4}, {BZ, 2, 2}, {RZ, 0, 4}, {BZ, 3, 3},
     {D, 0, 4}, {END, 0, 0}},
    {{RW, 0, 9}, {GW, 0, 9}, {BW, 0, 9}, {RX, 0, 3}, {RW, 10, 10}, {GZ, 4, 4}, {GY, 0, 3}, {GX, 0, 4}, {GW, 10, 10},
     {GZ, 0, 3}, {BX, 0, 3}, {BW, 10, 10}, {BZ, 1, 1}, {BY, 0, 3}, {RY, 0, 3}, {BZ, 0, 0}, {BZ, 2, 2}, {RZ, 0, 3},
     {GY, 4, 4}, {BZ, 3, 3}, {D, 0, 4}, {END, 0, 0}},
    {{RW, 0, 9}, {GW, 0, 9}, {BW, 0, 9}, {RX, 0, 3}, {RW, 10, 10}, {BY, 4, 4}, {GY, 0, 3}, {GX, 0, 3}, {GW, 10, 10},
     {BZ, 0, 0}, {GZ, 0, 3}, {BX, 0, 4}, {BW, 10, 10}, {BY, 0, 3}, {RY, 0, 3}, {BZ, 1, 1}, {BZ, 2, 2}, {RZ, 0, 3},
     {BZ, 4, 4}, {BZ, 3, 3}, {D, 0, 4}, {END, 0, 0}},
    {{RW, 0, 8}, {BY, 4, 4}, {GW, 0, 8}, {GY, 4, 4}, {BW, 0, 8}, {BZ, 4, 4}, {RX, 0, 4}, {GZ, 4, 4}, {GY, 0, 3},
     {GX, 0, 4}, {BZ, 0, 0}, {GZ, 0, 3}, {BX, 0, 4}, {BZ, 1, 1}, {BY, 0, 3}, {RY, 0, 4}, {BZ, 2, 2}, {RZ, 0, 4},
     {BZ, 3, 3}, {D, 0, 4}, {END, 0, 0}},
    {{RW, 0, 7}, {GZ, 4, 4}, {BY, 4, 4}, {GW, 0, 7}, {BZ, 2, 2}, {GY, 4, 4}, {BW, 0, 7}, {BZ, 3, 3}, {BZ, 4, 4},
     {RX, 0, 5}, {GY, 0, 3}, {GX, 0, 4}, {BZ, 0, 0}, {GZ, 0, 3}, {BX, 0, 4}, {BZ, 1, 1}, {BY, 0, 3}, {RY, 0, 5},
     {RZ, 0, 5}, {D, 0, 4}, {END, 0, 0}},
    {{RW, 0, 7}, {BZ, 0, 0}, {BY, 4, 4}, {GW, 0, 7}, {GY, 5, 5}, {GY, 4, 4}, {BW, 0, 7}, {GZ, 5, 5}, {BZ, 4, 4},
     {RX, 0, 4}, {GZ, 4, 4}, {GY, 0, 3}, {GX, 0, 5}, {GZ, 0, 3}, {BX, 0, 4}, {BZ, 1, 1}, {BY, 0, 3}, {RY, 0, 4},
     {BZ, 2, 2}, {RZ, 0, 4}, {BZ, 3, 3}, {D, 0, 4}, {END, 0, 0}},
    {{RW, 0, 7}, {BZ, 1, 1}, {BY, 4, 4}, {GW, 0, 7}, {BY, 5, 5}, {GY, 4, 4}, {BW, 0, 7}, {BZ, 5, 5}, {BZ, 4, 4},
     {RX, 0, 4}, {GZ, 4, 4}, {GY, 0, 3}, {GX, 0, 4}, {BZ, 0, 0}, {GZ, 0, 3}, {BX, 0, 5}, {BY, 0, 3}, {RY, 0, 4},
     {BZ, 2, 2}, {RZ, 0, 4}, {BZ, 3, 3}, {D, 0, 4}, {END, 0, 0}},
    {{RW, 0, 5}, {GZ, 4, 4}, {BZ, 0, 0}, {BZ, 1, 1}, {BY, 4, 4}, {GW, 0, 5}, {GY, 5, 5}, {BY, 5, 5}, {BZ, 2, 2},
     {GY, 4, 4}, {BW, 0, 5}, {GZ, 5, 5}, {BZ, 3, 3}, {BZ, 5, 5}, {BZ, 4, 4}, {RX, 0, 5}, {GY, 0, 3}, {GX, 0, 5},
     {GZ, 0, 3}, {BX, 0, 5}, {BY, 0, 3}, {RY, 0, 5}, {RZ, 0, 5}, {D, 0, 4}, {END, 0, 0}},
    {{RW, 0, 9}, {GW, 0, 9}, {BW, 0, 9}, {RX, 0, 9}, {GX, 0, 9}, {BX, 0, 9}, {END, 0, 0}},
    {{RW, 0, 9}, {GW, 0, 9}, {BW, 0, 9}, {RX, 0, 8}, {RW, 10, 10}, {GX, 0, 8}, {GW, 10, 10}, {BX, 0, 8}, {BW, 10, 10},
     {END, 0, 0}},
    {{RW, 0, 9}, {GW, 0, 9}, {BW, 0, 9}, {RX, 0, 7}, {RW, 11, 10}, {GX, 0, 7}, {GW, 11, 10}, {BX, 0, 7}, {BW, 11, 10},
     {END, 0, 0}},
    {{RW, 0, 9}, {GW, 0, 9}, {BW, 0, 9}, {RX, 0, 3}, {RW, 15, 10}, {GX, 0, 3}, {GW, 15, 10}, {BX, 0, 3}, {BW, 15, 10},
     {END, 0, 0}},
};

struct BitReader {
    const uint8_t* p;
    int pos = 0;
    int bit() {
        const int b = (p[pos >> 3] >> (pos & 7)) & 1;
        ++pos;
        return b;
    }
    int bits(int n) {
        int v = 0;
        for (int i = 0; i < n; ++i) v |= bit() << i;
        return v;
    }
};

struct BitWriter {
    uint8_t* p;
    int pos = 0;
    void bit(int b) {
        if (b & 1) p[pos >> 3] = uint8_t(p[pos >> 3] | (1 << (pos & 7)));
        ++pos;
    }
    void bits(int v, int n) {
        for (int i = 0; i < n; ++i) bit(v >> i);
    }
};

int sign_extend(int v, int bits) {
    const int m = 1 << (bits - 1);
    v &= (1 << bits) - 1;
    return (v ^ m) - m;
}

int index_bits(int regions, int partition, int t) {
    const int base = regions == 2 ? 3 : 4;
    return is_anchor(partition, regions, t) ? base - 1 : base;
}

} // namespace

int mode_of(const uint8_t block[16]) {
    int h = block[0] & 3;
    if (h >= 2) h = block[0] & 31;
    for (int m = 0; m < 14; ++m)
        if (kModes[m].header == h) return m;
    return -1;
}

bool unpack(const uint8_t block[16], bool is_signed, Logical& out) {
    const int m = mode_of(block);
    if (m < 0) return false;
    const ModeInfo& mi = kModes[m];
    BitReader r{block};
    r.pos = mi.header_bits;
    int raw[13] = {};
    for (const Run* run = kLayout[m]; run->field != END; ++run) {
        if (run->last >= run->first)
            for (int b = run->first; b <= run->last; ++b) raw[run->field] |= r.bit() << b;
        else
            for (int b = run->first; b >= run->last; --b) raw[run->field] |= r.bit() << b;
    }
    out.mode = m;
    out.partition = mi.regions == 2 ? raw[D] : 0;
    const int ends = 2 * mi.regions;
    for (int c = 0; c < 3; ++c) {
        const int e0 = is_signed ? sign_extend(raw[c], mi.w) : raw[c];
        out.e[0][c] = e0;
        for (int e = 1; e < ends; ++e) {
            int v = raw[3 * e + c];
            if (mi.transformed || is_signed) v = sign_extend(v, mi.d[c]);
            if (mi.transformed) {
                v = (e0 + v) & ((1 << mi.w) - 1);
                if (is_signed) v = sign_extend(v, mi.w);
            }
            out.e[e][c] = v;
        }
        for (int e = ends; e < 4; ++e) out.e[e][c] = 0;
    }
    for (int t = 0; t < 16; ++t) out.idx[t] = uint8_t(r.bits(index_bits(mi.regions, out.partition, t)));
    return true;
}

bool fits(int m, const int e[4][3], bool is_signed) {
    const ModeInfo& mi = kModes[m];
    // Signed codes stay symmetric: -2^(w-1) adds nothing below w = 16 (it unquantizes like
    // -(2^(w-1) - 1)) and at w = 16 it would finish to an infinity.
    const int lo = is_signed ? -((1 << (mi.w - 1)) - 1) : 0, hi = is_signed ? (1 << (mi.w - 1)) - 1 : (1 << mi.w) - 1;
    for (int k = 0; k < 2 * mi.regions; ++k)
        for (int c = 0; c < 3; ++c) {
            if (e[k][c] < lo || e[k][c] > hi) return false;
            if (k > 0 && mi.transformed) {
                const int dl = e[k][c] - e[0][c];
                if (dl < -(1 << (mi.d[c] - 1)) || dl > (1 << (mi.d[c] - 1)) - 1) return false;
            }
        }
    return true;
}

void pack(const Logical& in, bool is_signed, uint8_t block[16]) {
    (void)is_signed; // two's complement truncation is the same for both
    const ModeInfo& mi = kModes[in.mode];
    for (int i = 0; i < 16; ++i) block[i] = 0;
    int raw[13] = {};
    for (int c = 0; c < 3; ++c) {
        raw[c] = in.e[0][c] & ((1 << mi.w) - 1);
        for (int e = 1; e < 2 * mi.regions; ++e) {
            const int v = mi.transformed ? in.e[e][c] - in.e[0][c] : in.e[e][c];
            raw[3 * e + c] = v & ((1 << mi.d[c]) - 1);
        }
    }
    raw[D] = in.partition;
    BitWriter w{block};
    w.bits(mi.header, mi.header_bits);
    for (const Run* run = kLayout[in.mode]; run->field != END; ++run) {
        if (run->last >= run->first)
            for (int b = run->first; b <= run->last; ++b) w.bit(raw[run->field] >> b);
        else
            for (int b = run->first; b >= run->last; --b) w.bit(raw[run->field] >> b);
    }
    for (int t = 0; t < 16; ++t) w.bits(in.idx[t], index_bits(mi.regions, in.partition, t));
}

} // namespace detail::bc6h

int bc6h_block_mode(const uint8_t block[16]) { return detail::bc6h::mode_of(block) + 1; }

void decode_bc6h_block_half(const uint8_t block[16], bool is_signed, uint16_t out[48]) {
    using namespace detail::bc6h;
    Logical L;
    if (!unpack(block, is_signed, L)) {
        for (int i = 0; i < 48; ++i) out[i] = 0;
        return;
    }
    const ModeInfo& mi = kModes[L.mode];
    int u[4][3];
    for (int e = 0; e < 2 * mi.regions; ++e)
        for (int c = 0; c < 3; ++c) u[e][c] = unquantize(L.e[e][c], mi.w, is_signed);
    const int* weights = mi.regions == 2 ? kWeights3 : kWeights4;
    for (int t = 0; t < 16; ++t) {
        const int r = region_of(L.partition, mi.regions, t);
        for (int c = 0; c < 3; ++c)
            out[3 * t + c] = finish(interpolate(u[2 * r][c], u[2 * r + 1][c], weights[L.idx[t]]), is_signed);
    }
}

void decode_bc6h_block(const uint8_t block[16], bool is_signed, float out[48]) {
    uint16_t h[48];
    decode_bc6h_block_half(block, is_signed, h);
    for (int i = 0; i < 48; ++i) out[i] = detail::half_to_float(h[i]);
}

} // namespace atlas::compress

// BC4 decoding under each decoder model, and the endpoint search.
#include "atlas/compress/bc4.h"

#include "bc4_eval.h"
#include "palette_search.h"

#include <algorithm>
#include <mutex>
#include <list>
#include <cmath>
#include <cstring>
#include <vector>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

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

// The exact palette of a pair under one model, in double (num / (steps * scale) has a
// relative error of ~1e-16 there), for bounds that hold in exact arithmetic.
void palette_exact(uint8_t b0, uint8_t b1, bool snorm, Decoder d, double v[8]) {
    const int e0 = level(b0, snorm), e1 = level(b1, snorm);
    const double scale = snorm ? 127.0 : 255.0;
    const bool eight = snorm ? (static_cast<int8_t>(b0) > static_cast<int8_t>(b1)) : (b0 > b1);
    const bool integer = (d == Decoder::Tool8 || d == Decoder::Tool8Round);
    const bool round = d == Decoder::Tool8Round;
    v[0] = e0 / scale;
    v[1] = e1 / scale;
    const int steps = eight ? 7 : 5;
    const int count = eight ? 6 : 4;
    for (int k = 0; k < count; ++k) {
        const int num = (steps - 1 - k) * e0 + (k + 1) * e1;
        const int rounded = round ? (num >= 0 ? (num + steps / 2) / steps : (num - steps / 2) / steps) : num / steps;
        v[2 + k] = integer ? rounded / scale : num / (double(steps) * scale);
    }
    if (!eight) {
        v[6] = snorm ? -1.0 : 0.0;
        v[7] = 1.0;
    }
}

// The smallest float >= x (1 + 1e-15) and the largest <= x (1 - 1e-15) (for x >= 0;
// mirrored below 0): bounds of the exact value and of any double computation of it.
// Values a float holds exactly (0, +-1: the palettes' denominators are odd, so no
// other value is dyadic) are computed exactly in double too and stay as they are.
float float_up(double x) {
    if (double(float(x)) == x) return float(x);
    const double t = x + std::fabs(x) * 1e-15;
    float f = float(t);
    if (double(f) < t) f = std::nextafter(f, INFINITY);
    return f;
}
float float_down(double x) {
    if (double(float(x)) == x) return float(x);
    const double t = x - std::fabs(x) * 1e-15;
    float f = float(t);
    if (double(f) > t) f = std::nextafter(f, -INFINITY);
    return f;
}

// `exact_bounds`: lo / hi bound the exact values (the encoder's tables, so that its
// one-sided and max-error results hold in exact arithmetic); off for the public
// interval decode, which reports the float values the decoder models compute.
void interval_palette(uint8_t b0, uint8_t b1, bool snorm, DecoderSet set, detail::Palette<1>& p, bool exact_bounds = false) {
    p.n = 8;
    float ref[8];
    palette_values(b0, b1, snorm, Decoder::Reference, ref);
    for (int i = 0; i < 8; ++i) { p.ref[i][0] = ref[i]; p.lo[i][0] = ref[i]; p.hi[i][0] = ref[i]; }
    bool any = false;
    for (int di = 0; di < kDecoderCount; ++di) {
        if (!(set & (DecoderSet(1) << di))) continue; // no allocation: 65,536 palettes per encoder
        const Decoder d = static_cast<Decoder>(di);
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
    if (exact_bounds)
        for (int di = 0; di < kDecoderCount; ++di) {
            if (!(set & (DecoderSet(1) << di))) continue;
            const Decoder d = static_cast<Decoder>(di);
            double x[8];
            palette_exact(b0, b1, snorm, d == Decoder::Conformant ? Decoder::Reference : d, x);
            const bool eight = snorm ? (static_cast<int8_t>(b0) > static_cast<int8_t>(b1)) : (b0 > b1);
            for (int i = 0; i < 8; ++i) {
                const double t = (d == Decoder::Conformant && i >= 2 && i < (eight ? 8 : 6)) ? 1.0 / 255.0 : 0.0;
                p.lo[i][0] = std::min(p.lo[i][0], float_down(x[i] - t));
                p.hi[i][0] = std::max(p.hi[i][0], float_up(x[i] + t));
            }
        }
}

void write_block_bits(uint8_t b0, uint8_t b1, uint64_t bits, uint8_t out[8]) {
    // One 8-byte store, little-endian: b0, b1, then the 48 index bits from the lowest.
    uint8_t block[8] = {b0, b1};
    for (int i = 0; i < 6; ++i) block[2 + i] = uint8_t(bits >> (8 * i));
    std::memcpy(out, block, 8);
}

void write_block(uint8_t b0, uint8_t b1, const uint8_t idx[16], uint8_t out[8]) {
    uint64_t bits = 0;
    for (int t = 0; t < 16; ++t) bits |= uint64_t(idx[t] & 7) << (3 * t);
    write_block_bits(b0, b1, bits, out);
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

namespace {
struct PairTables {
    std::vector<detail::Palette<1>> pal; // index b0 * 256 + b1
    std::vector<float> pal_min;          // min lo over all entries (one-sided feasibility)
    // Range [imin, imax] of the entries other than the 6-value mode's exact constants
    // (lower bounds), whether the pair is in that mode, and per row b0 and mode the
    // extremes of those ranges (whole rows are skipped).
    std::vector<float> imin, imax;
    std::vector<uint8_t> six;
    std::vector<float> six_mask; // all bits set where six (SIMD blend)
    std::vector<float> ent_lo[8], ent_hi[8]; // entry i of every pair, pair-contiguous (SIMD probes)
    float row_imin[256][2], row_imax[256][2];
    float c_lo = 0, c_hi = 1; // the 6-value mode's constants
    // Spacing bound (search_all_pairs): the exact value of each endpoint byte, and the
    // largest |c - x_j| - h of any entry (interval centre c, half-width h over the
    // decoder set) against the exact, evenly spaced value x_j = lower + j (upper -
    // lower) / steps of its mode, over every pair.
    float val[256];
    double slack[2] = {-1, -1}; // [0]: 8-value mode, [1]: 6-value mode (may be < 0)
    // Every palette entry's interval depends only on its numerator: an endpoint on its
    // byte, an interpolated entry of mode m (0: 8 values, steps 7; 1: 6 values, steps 5)
    // on num = (steps - 1 - k) e0 + (k + 1) e1. These tables (a few KB, cache resident)
    // hold the same floats as `pal` and build fast/normal's candidate palettes, which
    // would otherwise be an L3 or memory miss per candidate.
    float end_lo[256], end_hi[256], end_ref[256];
    std::vector<float> num_lo[2], num_hi[2], num_ref[2];
    // The Reference decoder alone: the same floats as records {lo, hi, ref, 0} per
    // numerator, so that line_palette loads an entry's three with one load.
    std::vector<float> num_record[2];
    float grid_per[2][256] = {}; // the same: steps * scale / d, grid steps per unit value by level spread d
    int num_base[2] = {0, 0}; // index = num - num_base
    bool avx2 = false;        // fast / normal evaluate with AVX2 (same results, bc4_eval.h)
    // fast / normal's results for flat blocks on a level: 16 texels with the bits of
    // level L's float L / scale (8-bit sources; maps clamped at 0 or 1), at L - the
    // lowest level. Filled by the constructor with encode's own results, so a hit writes
    // the same bytes as the candidate search it replaces (36 ns -> 6 ns a block here).
    bool flat_ready = false;
    bool shortcuts = true; // the flat table and endpoints_only's skip (off: tests' reference)
    float flat_src[256];
    uint8_t flat_out[256][8];
    BlockResult flat_res[256];
};
} // namespace

struct Bc4Encoder::Tables : PairTables {};

namespace {
void build_tables(PairTables& T, bool snorm, DecoderSet decoders) {
    T.pal.resize(65536);
    T.pal_min.resize(65536);
    T.imin.resize(65536);
    T.imax.resize(65536);
    T.six.resize(65536);
    T.six_mask.resize(65536);
    for (int i = 0; i < 8; ++i) { T.ent_lo[i].resize(65536); T.ent_hi[i].resize(65536); }
    T.c_lo = snorm ? -1.0f : 0.0f;
    for (int r = 0; r < 256; ++r)
        for (int m = 0; m < 2; ++m) { T.row_imin[r][m] = INFINITY; T.row_imax[r][m] = -INFINITY; }
    const double vscale = snorm ? 127.0 : 255.0;
    for (int b = 0; b < 256; ++b) T.val[b] = float(level(uint8_t(b), snorm) / vscale);
    const int lmin = snorm ? -127 : 0, lmax = snorm ? 127 : 255;
    for (int m = 0; m < 2; ++m) {
        const int steps = m == 0 ? 7 : 5;
        T.num_base[m] = steps * lmin;
        const size_t n = size_t(steps * (lmax - lmin) + 1);
        T.num_lo[m].assign(n, NAN);
        T.num_hi[m].assign(n, NAN);
        T.num_ref[m].assign(n, NAN);
    }
    for (int k = 0; k < 65536; ++k) {
        const uint8_t b0 = uint8_t(k >> 8), b1 = uint8_t(k & 255);
        auto& p = T.pal[size_t(k)];
        interval_palette(b0, b1, snorm, decoders, p, true);
        const bool eight = snorm ? (static_cast<int8_t>(b0) > static_cast<int8_t>(b1)) : (b0 > b1);
        {
            // Entry i's place j on the exact grid: 8-value mode e1 + j (e0 - e1) / 7 with
            // entries 1, 7, 6, .., 2, 0 at j = 0..7; 6-value mode e0 + j (e1 - e0) / 5
            // with entries 0, 2, .., 5, 1.
            const double e0 = level(b0, snorm) / vscale, e1 = level(b1, snorm) / vscale;
            const int interp = eight ? 8 : 6;
            double& sl = T.slack[eight ? 0 : 1];
            for (int i = 0; i < interp; ++i) {
                double x;
                if (eight) x = i == 0 ? e0 : i == 1 ? e1 : e1 + double(8 - i) * (e0 - e1) / 7.0;
                else x = i == 0 ? e0 : i == 1 ? e1 : e0 + double(i - 1) * (e1 - e0) / 5.0;
                // error = max(hi - s, s - lo) = |s - c| + h (centre c, half-width h), so an
                // entry serving s within E has |s - x| <= E - h + |c - x|.
                const double c = 0.5 * (double(p.lo[i][0]) + double(p.hi[i][0])), h = 0.5 * (double(p.hi[i][0]) - double(p.lo[i][0]));
                sl = std::max(sl, std::fabs(c - x) - h);
            }
        }
        const int interp = eight ? 8 : 6;
        float mn = p.lo[0][0], imx = p.hi[0][0];
        for (int i = 1; i < 8; ++i) mn = std::min(mn, p.lo[i][0]);
        float imn = p.lo[0][0];
        for (int i = 1; i < interp; ++i) { imn = std::min(imn, p.lo[i][0]); imx = std::max(imx, p.hi[i][0]); }
        {
            const int e0 = level(b0, snorm), e1 = level(b1, snorm), m = eight ? 0 : 1, steps = eight ? 7 : 5;
            T.end_lo[b0] = p.lo[0][0]; T.end_hi[b0] = p.hi[0][0]; T.end_ref[b0] = p.ref[0][0];
            for (int i = 2; i < interp; ++i) {
                const size_t at = size_t((steps - 1 - (i - 2)) * e0 + (i - 1) * e1 - T.num_base[m]);
                T.num_lo[m][at] = p.lo[i][0]; T.num_hi[m][at] = p.hi[i][0]; T.num_ref[m][at] = p.ref[i][0];
            }
        }
        T.pal_min[size_t(k)] = mn;
        T.imin[size_t(k)] = imn;
        T.imax[size_t(k)] = imx;
        T.six[size_t(k)] = eight ? 0 : 1;
        for (int i = 0; i < 8; ++i) { T.ent_lo[i][size_t(k)] = p.lo[i][0]; T.ent_hi[i][size_t(k)] = p.hi[i][0]; }
        const uint32_t all_bits = eight ? 0u : 0xffffffffu;
        std::memcpy(&T.six_mask[size_t(k)], &all_bits, 4);
        const int m = eight ? 0 : 1;
        T.row_imin[b0][m] = std::min(T.row_imin[b0][m], imn);
        T.row_imax[b0][m] = std::max(T.row_imax[b0][m], imx);
    }
    // The Reference decoder alone: an endpoint e's floats are those of the numerator
    // steps * e (the same exact value, num / steps = e exactly), so the numerator tables
    // hold both and line_palette reads a pair's whole grid from one of them. (Under the
    // Conformant model interpolated entries are wider than endpoints: not filled there.)
    if (decoders != kReferenceOnly) return;
    for (int m = 0; m < 2; ++m) {
        for (int b = 0; b < 256; ++b) {
            const size_t at = size_t((m == 0 ? 7 : 5) * level(uint8_t(b), snorm) - T.num_base[m]);
            if (std::isnan(T.num_lo[m][at])) { T.num_lo[m][at] = T.end_lo[b]; T.num_hi[m][at] = T.end_hi[b]; T.num_ref[m][at] = T.end_ref[b]; }
        }
        T.num_record[m].assign(4 * T.num_lo[m].size(), 0.0f);
        for (size_t i = 0; i < T.num_lo[m].size(); ++i) {
            T.num_record[m][4 * i] = T.num_lo[m][i];
            T.num_record[m][4 * i + 1] = T.num_hi[m][i];
            T.num_record[m][4 * i + 2] = T.num_ref[m][i];
        }
        for (int d = 1; d < 256; ++d) T.grid_per[m][d] = float((m == 0 ? 7.0 : 5.0) * vscale / d);
    }
}

// fast / normal's candidate palette of pair k from the per-entry tables: the same
// floats as T.pal[k] (test Bc4Eval.EntryTablesEqualPairTables).
void entry_palette(const PairTables& T, int k, bool snorm, detail::Palette<1>& p) {
    const uint8_t b0 = uint8_t(k >> 8), b1 = uint8_t(k & 255);
    const int e0 = level(b0, snorm), e1 = level(b1, snorm);
    const bool eight = snorm ? (static_cast<int8_t>(b0) > static_cast<int8_t>(b1)) : (b0 > b1);
    p.n = 8;
    p.lo[0][0] = T.end_lo[b0]; p.hi[0][0] = T.end_hi[b0]; p.ref[0][0] = T.end_ref[b0];
    p.lo[1][0] = T.end_lo[b1]; p.hi[1][0] = T.end_hi[b1]; p.ref[1][0] = T.end_ref[b1];
    const int m = eight ? 0 : 1, steps = eight ? 7 : 5, interp = eight ? 8 : 6;
    const float* lo = T.num_lo[m].data() - T.num_base[m];
    const float* hi = T.num_hi[m].data() - T.num_base[m];
    const float* ref = T.num_ref[m].data() - T.num_base[m];
    for (int i = 2; i < interp; ++i) {
        const int num = (steps - i + 1) * e0 + (i - 1) * e1;
        p.lo[i][0] = lo[num]; p.hi[i][0] = hi[num]; p.ref[i][0] = ref[num];
    }
    if (!eight) {
        p.lo[6][0] = p.hi[6][0] = p.ref[6][0] = T.c_lo;
        p.lo[7][0] = p.hi[7][0] = p.ref[7][0] = 1.0f;
    }
}
} // namespace

namespace detail {
long bc4_entry_table_mismatches(bool snorm, DecoderSet set) {
    auto T = std::make_unique<PairTables>();
    build_tables(*T, snorm, set == 0 ? kReferenceOnly : set);
    long bad = 0;
    for (int k = 0; k < 65536; ++k) {
        Palette<1> p;
        entry_palette(*T, k, snorm, p);
        const Palette<1>& q = T->pal[size_t(k)];
        bad += p.n != q.n;
        for (int i = 0; i < 8; ++i)
            bad += std::memcmp(&p.lo[i][0], &q.lo[i][0], 4) != 0 || std::memcmp(&p.hi[i][0], &q.hi[i][0], 4) != 0 ||
                   std::memcmp(&p.ref[i][0], &q.ref[i][0], 4) != 0;
    }
    return bad;
}
} // namespace detail

namespace {
// The tables of the last few encoder kinds, shared by every encoder of that kind: building
// them cost 4.7 ms of CPU (17.7 ms with all six decoder models) per texture, paid again by
// every small DDS output and every tile (issue 49). Immutable once built; the key is
// everything they depend on (the flat table holds encode()'s results under the options).
struct TablesKey {
    bool snorm;
    BlockOptions options;
    bool operator==(const TablesKey&) const = default;
};
constexpr size_t kSharedTables = 4; // about 12-17 MB each

std::mutex& tables_mutex() {
    static std::mutex m;
    return m;
}
// Held as their base (the encoder's Tables is private to it); every entry is a Bc4Encoder::Tables.
std::list<std::pair<TablesKey, std::shared_ptr<PairTables>>>& shared_tables() {
    static std::list<std::pair<TablesKey, std::shared_ptr<PairTables>>> l; // most recent first
    return l;
}
} // namespace

Bc4Encoder::Bc4Encoder(bool snorm, const BlockOptions& options) : Bc4Encoder(snorm, options, true) {}

Bc4Encoder::Bc4Encoder(bool snorm, const BlockOptions& options, bool shared) : snorm_(snorm), options_(options) {
    if (options_.decoders == 0) options_.decoders = kReferenceOnly;
    const TablesKey key{snorm_, options_};
    if (shared) {
        std::lock_guard<std::mutex> lock(tables_mutex());
        auto& l = shared_tables();
        for (auto it = l.begin(); it != l.end(); ++it)
            if (it->first == key) {
                tables_ = std::static_pointer_cast<Tables>(it->second);
                l.splice(l.begin(), l, it);
                return;
            }
    }
    // Built outside the lock (encoders of other kinds go on meanwhile); two threads building
    // the same kind at once each build it, and the later one is kept: the same bytes.
    tables_ = std::make_shared<Tables>();
    build_tables(*tables_, snorm_, options_.decoders);
    tables_->avx2 = detail::bc4_cpu_has_avx2();
    if (options_.quality != Quality::Best) { // best's exhaustive search per level would cost seconds
        const int lmin = snorm_ ? -127 : 0, lmax = snorm_ ? 127 : 255;
        const float scale = snorm_ ? 127.0f : 255.0f;
        for (int l = lmin; l <= lmax; ++l) {
            const int i = l - lmin;
            float src[16];
            std::fill(src, src + 16, float(l) / scale);
            tables_->flat_src[i] = src[0];
            tables_->flat_res[i] = encode(src, tables_->flat_out[i]);
        }
        tables_->flat_ready = true;
    }
    if (shared) {
        std::lock_guard<std::mutex> lock(tables_mutex());
        auto& l = shared_tables();
        l.remove_if([&](const auto& e) { return e.first == key; });
        l.emplace_front(key, tables_);
        while (l.size() > kSharedTables) l.pop_back();
    }
}

Bc4Encoder::~Bc4Encoder() = default;

namespace detail {
long bc4_shortcut_mismatches(bool snorm, const BlockOptions& options, const float* blocks, size_t count) {
    Bc4Encoder enc(snorm, options, false); // its own tables: the shortcuts are switched below
    PairTables& T = *enc.tables_;
    long bad = 0;
    auto same = [](const uint8_t* a, const BlockResult& x, const uint8_t* b, const BlockResult& y) {
        return std::memcmp(a, b, 8) == 0 && std::memcmp(&x.max_error, &y.max_error, 4) == 0 && std::memcmp(&x.sum_sq, &y.sum_sq, 8) == 0 &&
               x.one_sided_ok == y.one_sided_ok;
    };
    std::vector<uint8_t> run(8 * count);
    std::vector<BlockResult> run_res(count);
    enc.encode_blocks(blocks, count, run.data(), run_res.data());
    for (size_t b = 0; b < count; ++b) {
        uint8_t with[8], without[8];
        const BlockResult x = enc.encode(blocks + 16 * b, with);
        T.shortcuts = false;
        const BlockResult y = enc.encode(blocks + 16 * b, without);
        T.shortcuts = true;
        bad += !same(with, x, without, y) || !same(&run[8 * b], run_res[b], without, y);
    }
    return bad;
}

} // namespace detail

namespace {

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

// The 6-value pair (L, H) after the 8-value incumbent (H, L) whose every texel took an
// endpoint (index 0 or 1), under narrow intervals (the Reference decoder alone), with
// the texels within [L, H]: the 6-value pair cannot win, so it is not evaluated. Its
// endpoints are the same bytes, so the same intervals and per-texel errors there; each
// texel is within (H - L) / 14 (+ ulps) of its endpoint (the 8 entries' nearest), its
// interpolated entries are at least (H - L) / 5 from both endpoints, and its constants 0
// and 1 (SNORM -1, 1) lie beyond L and H. So every texel's key error is at least the
// incumbent's, and so are the max and the sum (in the same order): no strict improvement.
// (On 8-bit images most blocks two levels wide end here: 12,400 of the cloud render's
// 16,000 non-flat blocks evaluated the 6-value pair in full to tie and lose.)
int swapped(int k) { return ((k & 255) << 8) | (k >> 8); }
bool endpoints_only(const detail::Bc4Keys& keys) {
    uint32_t any = 0;
    for (int t = 0; t < 16; ++t) any |= keys.key[t] & 6u; // index 0 or 1: bits 1 and 2 clear
    return any == 0;
}

// A flat block on a level, from the table (its float must have the level's bits).
bool flat_from_table(const PairTables& T, float v, bool snorm, uint8_t out[8], BlockResult& r) {
    const float scale = snorm ? 127.0f : 255.0f;
    const int lo_lim = snorm ? -127 : 0, hi_lim = snorm ? 127 : 255;
    const float x = v * scale;
    if (!(x >= float(lo_lim) && x <= float(hi_lim))) return false; // finite, so the rounding below is defined
    const int i = int(x + (x >= 0 ? 0.5f : -0.5f)) - lo_lim;
    if (std::memcmp(&v, &T.flat_src[i], 4) != 0) return false;
    std::memcpy(out, T.flat_out[i], 8);
    r = T.flat_res[i];
    return true;
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

#if defined(ATLAS_BC4_AVX2)
// The line palette (bc4_eval.h) of the pair on levels lo < hi: the 8-value mode (hi, lo)
// or the 6-value mode (lo, hi); the Reference decoder alone (build_tables' numerator
// slots at the endpoints). Grid value j has the numerator steps * lo + j (hi - lo).
__attribute__((target("avx2"), always_inline)) inline void line_palette(const PairTables& T, int lo, int hi, bool eight, detail::Bc4LinePalette& p) {
    // 8 values: entry 1 (lo), 7, 6, .., 2, 0 (hi); 6 values: the constant below (6), 0
    // (lo), 2, .., 5, 1 (hi), the constant above (7).
    static constexpr int32_t kIndex[2][8] = {{1, 7, 6, 5, 4, 3, 2, 0}, {6, 0, 2, 3, 4, 5, 1, 7}};
    const int m = eight ? 0 : 1, steps = eight ? 7 : 5;
    const int at = steps * lo - T.num_base[m], d = hi - lo;
    // Grid value j's record at r + j * stride; two records per load (one in each lane),
    // then a 4 x 4 transpose within the lanes gives lo, hi and ref for the 8 positions.
    // The 6-value mode's lanes 0 and 7 (its constants) load a grid end and are replaced.
    const float* r = T.num_record[m].data() + 4 * size_t(at);
    const size_t stride = 4 * size_t(d);
    auto pair_of = [&](int j0, int j1) __attribute__((target("avx2"))) { return _mm256_loadu2_m128(r + size_t(j1) * stride, r + size_t(j0) * stride); };
    const __m256 a0 = eight ? pair_of(0, 4) : pair_of(0, 3), a1 = eight ? pair_of(1, 5) : pair_of(0, 4);
    const __m256 a2 = eight ? pair_of(2, 6) : pair_of(1, 5), a3 = eight ? pair_of(3, 7) : pair_of(2, 5);
    const __m256d t0 = _mm256_castps_pd(_mm256_unpacklo_ps(a0, a1)), t1 = _mm256_castps_pd(_mm256_unpacklo_ps(a2, a3));
    const __m256d t2 = _mm256_castps_pd(_mm256_unpackhi_ps(a0, a1)), t3 = _mm256_castps_pd(_mm256_unpackhi_ps(a2, a3));
    p.lo = _mm256_castpd_ps(_mm256_unpacklo_pd(t0, t1));
    p.hi = _mm256_castpd_ps(_mm256_unpackhi_pd(t0, t1));
    p.ref = _mm256_castpd_ps(_mm256_unpacklo_pd(t2, t3));
    if (!eight) {
        const __m256 constants = _mm256_setr_ps(T.c_lo, 0, 0, 0, 0, 0, 0, T.c_hi);
        p.lo = _mm256_blend_ps(p.lo, constants, 0x81);
        p.hi = _mm256_blend_ps(p.hi, constants, 0x81);
        p.ref = _mm256_blend_ps(p.ref, constants, 0x81);
    }
    p.index = kIndex[m];
    // The exact grid's spacing (no division on the chain; the floats' grid is within
    // ulps of it, and the keys need the position only to within half a step).
    p.origin = r[2];
    p.per_value = T.grid_per[m][d];
    p.offset = (eight ? 0.0f : 1.0f) - p.origin * p.per_value;
}

// Whether the 6-value pair of a level pair can hold every texel within the 8-value
// incumbent's max error E, from the texels' distances to its even grid (the 8-value
// evaluation's six_far: in grid steps, through the 8-value line's position and spacing,
// the same grid value, 5 steps instead of 7). The distance computed so is within ~3e-7
// of the exact one in value (values within +-2), and the 6-value pair's key errors are
// at least the exact distances less 8 ulps (its constants lie on or beyond its grid ends
// and are never nearer than they), so a texel more than E + 1e-5 away fails that pair:
// its evaluation would return false (max error above the incumbent's). On 8-bit sources
// the two modes' errors are multiples of 1/35 level (1.1e-4), so every pair whose max
// error is the larger is skipped here.
__attribute__((target("avx2"), always_inline)) inline bool six_may_tie(const detail::Bc4LinePalette& eight, const detail::Bc4LineResult& r) {
    return !(r.six_far > (r.keys.max_err + 1e-5f) * eight.per_value * (5.0f / 7.0f));
}

BlockResult encode_candidates(const PairTables& T, bool snorm, const BlockOptions& options, const float src[16], uint8_t out[8]);

// Level pairs: the extremes' floor and ceiling (as encode computes them, clamped to the
// levels) are the levels lo < hi, so the candidate loop's pairs are (hi, lo) then (lo,
// hi) unless fast; the Reference decoder alone, two-sided, finite texels within +-2 and
// none -0.0 (which has the error -0.0 at an entry 0, as +0 - -0 < -0 - 0 is false: two
// such entries, the constant 0 on the grid's end 0, would tie the other way round).
struct LevelPair { // classify's, read only for its level pairs (no initializers: runs hold 128)
    int lo, hi;
    float smin, smax;
};
enum class BlockKind { Other, Flat, LevelPair };

__attribute__((target("avx2"), always_inline)) inline BlockKind classify(const float src[16], bool snorm, LevelPair& lp) {
    // Flat blocks leave early (they need none of the rest); the other tests are combined
    // without branches.
    const __m256 a = _mm256_loadu_ps(src), b = _mm256_loadu_ps(src + 8);
    const __m256i ai = _mm256_castps_si256(a), bi = _mm256_castps_si256(b);
    const __m256i first = _mm256_broadcastd_epi32(_mm256_castsi256_si128(ai));
    if (_mm256_movemask_epi8(_mm256_and_si256(_mm256_cmpeq_epi32(ai, first), _mm256_cmpeq_epi32(bi, first))) == -1) return BlockKind::Flat;
    __m256 mn = _mm256_min_ps(a, b), mx = _mm256_max_ps(a, b);
    __m128 mn4 = _mm_min_ps(_mm256_castps256_ps128(mn), _mm256_extractf128_ps(mn, 1)), mx4 = _mm_max_ps(_mm256_castps256_ps128(mx), _mm256_extractf128_ps(mx, 1));
    mn4 = _mm_min_ps(mn4, _mm_movehl_ps(mn4, mn4));
    mx4 = _mm_max_ps(mx4, _mm_movehl_ps(mx4, mx4));
    mn4 = _mm_min_ss(mn4, _mm_shuffle_ps(mn4, mn4, 1));
    mx4 = _mm_max_ss(mx4, _mm_shuffle_ps(mx4, mx4, 1));
    lp.smin = _mm_cvtss_f32(mn4);
    lp.smax = _mm_cvtss_f32(mx4);
    // Every texel within +-2 (its magnitude's bits at most 2.0f's: NaN and infinities fail,
    // which MINPS / MAXPS may skip) and none -0.0, on the bits.
    const __m256i magnitude = _mm256_set1_epi32(0x7fffffff), two = _mm256_set1_epi32(0x40000000), negative_zero = _mm256_set1_epi32(int(0x80000000u));
    const __m256i bad = _mm256_or_si256(_mm256_or_si256(_mm256_cmpgt_epi32(_mm256_and_si256(ai, magnitude), two), _mm256_cmpgt_epi32(_mm256_and_si256(bi, magnitude), two)),
                                        _mm256_or_si256(_mm256_cmpeq_epi32(ai, negative_zero), _mm256_cmpeq_epi32(bi, negative_zero)));
    const bool usable = _mm256_testz_si256(bad, bad);
    // The extremes' floor and ceiling, clamped to the levels (as encode computes them; the
    // clamp first keeps the conversion defined), in one register: smin, smax.
    const float scale = snorm ? 127.0f : 255.0f;
    const __m128 lim_lo = _mm_set1_ps(snorm ? -127.0f : 0.0f), lim_hi = _mm_set1_ps(snorm ? 127.0f : 255.0f);
    const __m128 x = _mm_mul_ps(_mm_unpacklo_ps(mn4, mx4), _mm_set1_ps(scale));
    const __m128 fl = _mm_min_ps(_mm_max_ps(_mm_floor_ps(x), lim_lo), lim_hi), cl = _mm_min_ps(_mm_max_ps(_mm_ceil_ps(x), lim_lo), lim_hi);
    const __m128i level = _mm_cvttps_epi32(fl);
    lp.lo = _mm_cvtsi128_si32(level);
    lp.hi = _mm_extract_epi32(level, 1);
    const bool levels = (_mm_movemask_ps(_mm_cmpeq_ps(fl, cl)) & 3) == 3;
    return (usable & levels & (lp.lo < lp.hi)) ? BlockKind::LevelPair : BlockKind::Other;
}

// The byte of a level (SNORM: its two's complement).
int level_byte(int v, bool snorm) { return int(snorm ? uint8_t(int8_t(v)) : uint8_t(v)); }

// N level pairs' first candidates, (hi, lo), each evaluated by its line palette (the same
// keys and results as the candidate loop's evaluation); ok[b] false if one fails (it
// cannot: every key error is finite), which leaves that block to the loop.
struct EightValues {
    detail::Bc4LinePalette pal;
    detail::Bc4LineResult r;
    int k = -1;
};
template <int N>
__attribute__((target("avx2"), always_inline)) inline void eight_values(const PairTables& T, const float* const src[N], const LevelPair* const lp[N],
                                                                       bool snorm, EightValues e[N], bool ok[N]) {
    const detail::Bc4LinePalette* pal[N];
    detail::Bc4LineResult* r[N];
    for (int b = 0; b < N; ++b) {
        e[b].k = level_byte(lp[b]->hi, snorm) * 256 + level_byte(lp[b]->lo, snorm);
        line_palette(T, lp[b]->lo, lp[b]->hi, true, e[b].pal);
        pal[b] = &e[b].pal;
        r[b] = &e[b].r;
    }
    detail::bc4_line_select_avx2<N, true>(pal, src, r, ok);
}

// N level pairs' second candidates, (lo, hi).
template <int N>
__attribute__((target("avx2"), always_inline)) inline void six_values(const PairTables& T, const float* const src[N], const LevelPair* const lp[N],
                                                                     detail::Bc4LineResult r6[N], bool ok[N]) {
    detail::Bc4LinePalette pal6[N];
    const detail::Bc4LinePalette* pal[N];
    detail::Bc4LineResult* r[N];
    for (int b = 0; b < N; ++b) {
        line_palette(T, lp[b]->lo, lp[b]->hi, false, pal6[b]);
        pal[b] = &pal6[b];
        r[b] = &r6[b];
    }
    detail::bc4_line_select_avx2<N>(pal, src, r, ok);
}

// Whether the loop would evaluate the second candidate, (lo, hi), and it could win: not
// after an exact incumbent or endpoints_only's, nor when six_may_tie rules it out.
__attribute__((target("avx2"), always_inline)) inline bool six_needed(const PairTables& T, const LevelPair& lp, const EightValues& e) {
    // Without branches: the keys come late in a block's chain, and a branch on them
    // (mispredicted for about one block in six) costs more than all three tests.
    const int k6 = swapped(e.k);
    const bool exact = (e.r.keys.max_err == 0.0f) & (e.r.keys.sum == 0.0f);
    const bool ends = e.r.endpoints & (lp.smin >= T.end_lo[k6 >> 8]) & (lp.smax <= T.end_hi[k6 & 255]);
    return !exact & !ends & six_may_tie(e.pal, e.r);
}

// The second candidate beats the first: a lower max error, or the same and a lower sum
// (what the loop's evaluation against the incumbent's stop and sum returns, bc4_eval.h).
bool six_beats(bool ok, const detail::Bc4Keys& six, float eight_max, float eight_sum) {
    return ok && (six.max_err < eight_max || (six.max_err == eight_max && six.sum < eight_sum));
}

void write_line_result(int k, const detail::Bc4LineResult& r, uint8_t out[8], BlockResult& res) {
    write_block_bits(uint8_t(k >> 8), uint8_t(k & 255), r.bits, out);
    res = {r.max_err, r.sum_sq, true};
}

// level_pair_blocks (below) for one block, with branches: encode's path (a run of one
// through those passes took 1.3-1.6x this one's time). Returns false for any other block,
// and for a level pair missing the bound (encode_candidates then does it all, to the same
// result).
__attribute__((target("avx2"))) bool level_pair_block(const PairTables& T, const float src[16], bool snorm, bool with_six, float bound, uint8_t out[8],
                                                     BlockResult& res) {
    LevelPair lp;
    const BlockKind kind = classify(src, snorm, lp);
    if (kind == BlockKind::Flat) return T.flat_ready && flat_from_table(T, src[0], snorm, out, res);
    if (kind != BlockKind::LevelPair) return false;
    const float* const in[1] = {src};
    const LevelPair* const pairs[1] = {&lp};
    EightValues e[1];
    detail::Bc4LineResult r6[1];
    bool ok[1], ok6[1];
    eight_values<1>(T, in, pairs, snorm, e, ok);
    if (!ok[0]) return false;
    bool six = with_six && six_needed(T, lp, e[0]);
    if (six) {
        six_values<1>(T, in, pairs, r6, ok6);
        six = six_beats(ok6[0], r6[0].keys, e[0].r.keys.max_err, e[0].r.keys.sum);
    }
    const detail::Bc4LineResult& r = six ? r6[0] : e[0].r;
    if (bound >= 0 && r.max_err > bound) return false;
    write_line_result(six ? swapped(e[0].k) : e[0].k, r, out, res);
    return true;
}

// encode's first steps for fast / normal under the Reference decoder alone, two-sided,
// on AVX2, for a run of blocks: flat blocks from the table, level pairs on their line
// palettes (8-bit sources: nearly every block), everything else and level pairs missing
// the bound by encode_candidates, to the same results (test Bc4.ShortcutsEqualTheSearch).
// In passes over blocks of one kind, so that no branch on a block's kind or on whether
// its 6-value pair is evaluated (both data dependent, and decided late in a block's
// chain) throws away the work on the blocks after it.
__attribute__((target("avx2"))) void level_pair_blocks(const PairTables& T, bool snorm, const BlockOptions& options, const float* src, size_t count,
                                                      uint8_t* out, BlockResult* res) {
    constexpr size_t kRun = 128;
    const bool with_six = options.quality != Quality::Fast;
    const float bound = options.max_error;
    for (size_t r0 = 0; r0 < count; r0 += kRun) {
        const size_t n = std::min(kRun, count - r0);
        const float* s = src + 16 * r0;
        uint8_t* o = out + 8 * r0;
        BlockResult* q = res + r0;
        uint16_t list[3][kRun], six[kRun];
        size_t len[3] = {0, 0, 0}, nsix = 0;
        LevelPair lp[kRun];
        float eight_max[kRun], eight_sum[kRun]; // the first candidate's (the second's comparison)
        int k8[kRun];
        bool more[kRun], redo[kRun]; // per block: no list appends in the passes' chains
        uint8_t kind[kRun];
        for (size_t i = 0; i < n; ++i) {
            kind[i] = uint8_t(classify(s + 16 * i, snorm, lp[i]));
            more[i] = redo[i] = false;
        }
        for (size_t i = 0; i < n; ++i) list[kind[i]][len[kind[i]]++] = uint16_t(i);
        for (size_t j = 0; j < len[int(BlockKind::Flat)]; ++j) {
            const size_t i = list[int(BlockKind::Flat)][j];
            redo[i] = !(T.flat_ready && flat_from_table(T, s[16 * i], snorm, o + 8 * i, q[i]));
        }
        // Level pairs two at a time (bc4_line_select_avx2's interleaving): a group's blocks
        // from position j of a list of `listed` (the last of an odd list alone).
        constexpr int kPair = 2;
        struct Group {
            int m;
            size_t at[kPair];
            const float* in[kPair];
            const LevelPair* pairs[kPair];
        };
        auto group = [&](const uint16_t* ids, size_t j, size_t listed) {
            Group g;
            g.m = int(std::min<size_t>(kPair, listed - j));
            for (int b = 0; b < g.m; ++b) {
                g.at[b] = ids[j + size_t(b)];
                g.in[b] = s + 16 * g.at[b];
                g.pairs[b] = &lp[g.at[b]];
            }
            return g;
        };
        const size_t npairs = len[int(BlockKind::LevelPair)];
        for (size_t j = 0; j < npairs; j += kPair) {
            const Group g = group(list[int(BlockKind::LevelPair)], j, npairs);
            EightValues e[kPair];
            bool ok[kPair];
            if (g.m == kPair) eight_values<kPair>(T, g.in, g.pairs, snorm, e, ok);
            else eight_values<1>(T, g.in, g.pairs, snorm, e, ok); // a single block (encode) or an odd run's last
            for (int b = 0; b < g.m; ++b) {
                const size_t i = g.at[b];
                write_line_result(e[b].k, e[b].r, o + 8 * i, q[i]);
                more[i] = ok[b] & with_six & six_needed(T, lp[i], e[b]);
                eight_max[i] = e[b].r.keys.max_err;
                eight_sum[i] = e[b].r.keys.sum;
                k8[i] = e[b].k;
                redo[i] = (!ok[b]) | ((!more[i]) & (bound >= 0) & (e[b].r.max_err > bound));
            }
        }
        for (size_t i = 0; i < n; ++i) {
            six[nsix] = uint16_t(i);
            nsix += more[i] ? 1 : 0;
        }
        // The second candidates, two at a time too.
        for (size_t j = 0; j < nsix; j += kPair) {
            const Group g = group(six, j, nsix);
            detail::Bc4LineResult r6[kPair];
            bool ok[kPair];
            if (g.m == kPair) six_values<kPair>(T, g.in, g.pairs, r6, ok);
            else six_values<1>(T, g.in, g.pairs, r6, ok);
            for (int b = 0; b < g.m; ++b) {
                const size_t i = g.at[b];
                if (six_beats(ok[b], r6[b].keys, eight_max[i], eight_sum[i])) write_line_result(swapped(k8[i]), r6[b], o + 8 * i, q[i]);
                redo[i] = bound >= 0 && q[i].max_error > bound;
            }
        }
        auto& other = list[int(BlockKind::Other)];
        size_t& nother = len[int(BlockKind::Other)];
        for (size_t i = 0; i < n; ++i)
            if (redo[i]) other[nother++] = uint16_t(i);
        for (size_t j = 0; j < nother; ++j) {
            const size_t i = other[j];
            q[i] = encode_candidates(T, snorm, options, s + 16 * i, o + 8 * i);
        }
    }
}
#endif

// Where level_pair_blocks applies (the CPU and the options; a block's kind aside).
bool level_pairs_apply(const PairTables& T, const BlockOptions& o) {
    return T.avx2 && T.shortcuts && o.decoders == kReferenceOnly && !o.one_sided_below && o.quality != Quality::Best;
}
} // namespace

namespace {
// encode's candidate search for any block (the level-pair path aside), apart so that
// encode's level-pair path does not pay this function's frame.
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
} // namespace

BlockResult Bc4Encoder::encode(const float src[16], uint8_t out[8]) const {
#if defined(ATLAS_BC4_AVX2)
    BlockResult r;
    if (level_pairs_apply(*tables_, options_) && level_pair_block(*tables_, src, snorm_, options_.quality != Quality::Fast, options_.max_error, out, r))
        return r;
#endif
    return encode_candidates(*tables_, snorm_, options_, src, out);
}

void Bc4Encoder::encode_blocks(const float* src, size_t count, uint8_t* out, BlockResult* results) const {
#if defined(ATLAS_BC4_AVX2)
    // Level pairs (8-bit sources: nearly every block not flat) take the same candidates
    // and give the same result through their line palettes (bc4_eval.h).
    if (level_pairs_apply(*tables_, options_)) {
        level_pair_blocks(*tables_, snorm_, options_, src, count, out, results);
        return;
    }
#endif
    for (size_t b = 0; b < count; ++b) results[b] = encode_candidates(*tables_, snorm_, options_, src + 16 * b, out + 8 * b);
}

namespace detail {
// Test hook (bc4_eval.h): the line palettes' evaluations of the level pair (lo, hi), both
// modes, against the full evaluation of the same pairs' palettes in index order.
#if defined(ATLAS_BC4_AVX2)
namespace {
__attribute__((target("avx2"))) long line_mismatches_avx2(const PairTables* T, bool snorm, const float* blocks, size_t count, int lo, int hi) {
    long bad = 0;
    const LevelPair pair{lo, hi, 0.0f, 0.0f};
    const LevelPair* const pairs[1] = {&pair};
    for (size_t b = 0; b < count; ++b) {
        const float* const in[1] = {blocks + 16 * b};
        EightValues e[1];
        detail::Bc4LineResult six[1];
        bool ok[2];
        eight_values<1>(*T, in, pairs, snorm, e, ok);
        six_values<1>(*T, in, pairs, six, ok + 1);
        const detail::Bc4LineResult* r[2] = {&e[0].r, &six[0]};
        detail::Bc4Keys full[2];
        for (int m = 0; m < 2; ++m) {
            const detail::Palette<1>& p = T->pal[size_t(m == 0 ? e[0].k : swapped(e[0].k))];
            const bool fok = detail::bc4_keys_portable<false>(p, in[0], detail::kBc4Infeasible, INFINITY, full[m]);
            float mx;
            double sq;
            uint64_t bits;
            detail::bc4_exact_portable<false>(p, in[0], full[m], mx, sq, bits);
            bad += ok[m] != fok || std::memcmp(r[m]->keys.key, full[m].key, sizeof full[m].key) != 0 ||
                   std::memcmp(&r[m]->keys.max_err, &full[m].max_err, 4) != 0 || std::memcmp(&r[m]->keys.sum, &full[m].sum, 4) != 0 ||
                   std::memcmp(&r[m]->max_err, &mx, 4) != 0 || std::memcmp(&r[m]->sum_sq, &sq, 8) != 0 || r[m]->bits != bits ||
                   r[m]->endpoints != endpoints_only(full[m]);
            // six_may_tie's skip: the 6-value pair's evaluation against the 8-value incumbent returns false.
            if (m == 1 && !six_may_tie(e[0].pal, e[0].r)) {
                detail::Bc4Keys tied;
                bad += detail::bc4_keys_portable<false>(p, in[0], full[0].max_err, full[0].sum, tied) ? 1 : 0;
            }
        }
    }
    return bad;
}
} // namespace
#endif

long bc4_line_mismatches(bool snorm, const float* blocks, size_t count, int lo, int hi) {
#if defined(ATLAS_BC4_AVX2)
    if (!bc4_cpu_has_avx2()) return 0;
    auto T = std::make_unique<PairTables>();
    build_tables(*T, snorm, kReferenceOnly);
    return line_mismatches_avx2(T.get(), snorm, blocks, count, lo, hi);
#else
    (void)snorm, (void)blocks, (void)count, (void)lo, (void)hi;
    return 0;
#endif
}
} // namespace detail

} // namespace atlas::compress

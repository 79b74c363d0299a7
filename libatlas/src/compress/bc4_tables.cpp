// BC4 encoder tables: every pair's palette and the search's pruning tables, built per encoder kind and shared.
#include "atlas/compress/bc4.h"

#include "bc4_internal.h"
#include "bc4_test_hooks.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <list>
#include <memory>
#include <mutex>
#include <vector>

namespace atlas::compress {

namespace detail::bc4 {

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

void fill_tables(PairTables& T, bool snorm, const BlockOptions& options) {
    build_tables(T, snorm, options.decoders);
    T.avx2 = detail::bc4_cpu_has_avx2();
    if (options.quality != Quality::Best) { // best's exhaustive search per level would cost seconds
        const int lmin = snorm ? -127 : 0, lmax = snorm ? 127 : 255;
        const float scale = snorm ? 127.0f : 255.0f;
        for (int l = lmin; l <= lmax; ++l) {
            const int i = l - lmin;
            float src[16];
            std::fill(src, src + 16, float(l) / scale);
            T.flat_src[i] = src[0];
            T.flat_res[i] = encode_block(T, snorm, options, src, T.flat_out[i]);
        }
        T.flat_ready = true;
    }
}

} // namespace detail::bc4

namespace detail {
long bc4_entry_table_mismatches(bool snorm, DecoderSet set) {
    auto T = std::make_unique<bc4::PairTables>();
    bc4::build_tables(*T, snorm, set == 0 ? kReferenceOnly : set);
    long bad = 0;
    for (int k = 0; k < 65536; ++k) {
        Palette<1> p;
        bc4::entry_palette(*T, k, snorm, p);
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
using detail::bc4::PairTables;

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

Bc4Encoder::Bc4Encoder(bool snorm, const BlockOptions& options) : snorm_(snorm), options_(detail::bc4::encoder_options(options)) {
    const TablesKey key{snorm_, options_};
    {
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
    detail::bc4::fill_tables(*tables_, snorm_, options_);
    {
        std::lock_guard<std::mutex> lock(tables_mutex());
        auto& l = shared_tables();
        l.remove_if([&](const auto& e) { return e.first == key; });
        l.emplace_front(key, tables_);
        while (l.size() > kSharedTables) l.pop_back();
    }
}

Bc4Encoder::~Bc4Encoder() = default;

} // namespace atlas::compress

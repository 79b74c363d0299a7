// Internal to the render module: the 2.5D density model (layer.cpp marches it).
// LayerModel turns a LayerScene into density at a point of the shell: coverage
// and the vertical profile from the NDF set and its LUT, the HZD base noise
// eroded by curl-distorted detail noise, wind, anvil and vortex rings
// (formulas in docs/render.md, "2.5D mode").
#pragma once

#include "atlas/core/error.h"
#include "atlas/core/hash.h"
#include "atlas/ndf/hzd_shape.h"
#include "atlas/render/layer.h"
#include "render_common.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace atlas::render::layer_detail {


inline void need(bool ok, const std::string& what) {
    if (!ok) throw Error("render (2.5D): " + what);
}

inline bool positive_finite(double v) { return v > 0 && std::isfinite(v); }

// The lookups below run several times per density sample (tens of millions
// per frame). GCC kept lerp2, wrap_axis and Noise3::sample as calls (~30 % of
// a 2.5D frame's perf samples); forced inline, fc6_forecast's frame takes 11 %
// fewer instructions with the same bytes (docs/PERFORMANCE.md, 2026-12-03).
#define ATLAS_LAYER_INLINE inline __attribute__((always_inline))

// Bilinear lookup of a 2D field at texel coordinate (u, v) (centres at
// i + 0.5) with wrap or clamp addressing.
struct Bilinear {
    int x0, x1, y0, y1;
    float tx, ty;
};

using detail::axis_clamp;
using detail::axis_wrap;

// axis_wrap for n a power of two (mask = n - 1): the same texels and weight
// (two's complement & is the positive modulo) without an integer division.
ATLAS_LAYER_INLINE void axis_wrap_pow2(double u, int mask, int& i0, int& i1, float& t) {
    u -= 0.5;
    const double f = std::floor(u);
    t = static_cast<float>(u - f);
    i0 = static_cast<int>(static_cast<long long>(f) & mask);
    i1 = (i0 + 1) & mask;
}
inline bool is_pow2(int n) { return n > 0 && (n & (n - 1)) == 0; }
// axis_wrap, or its division-free form when mask >= 0 (n a power of two).
ATLAS_LAYER_INLINE void wrap_axis(double u, int n, int mask, int& i0, int& i1, float& t) {
    if (mask >= 0) axis_wrap_pow2(u, mask, i0, i1, t);
    else axis_wrap(u, n, i0, i1, t);
}

ATLAS_LAYER_INLINE float lerp2(const float* p, int nx, const Bilinear& b) {
    const float* r0 = p + size_t(b.y0) * size_t(nx);
    const float* r1 = p + size_t(b.y1) * size_t(nx);
    const float a = r0[b.x0] + (r0[b.x1] - r0[b.x0]) * b.tx;
    const float c = r1[b.x0] + (r1[b.x1] - r1[b.x0]) * b.tx;
    return a + (c - a) * b.ty;
}

// A tiling 3D noise with up to 4 channels, trilinear, stored interleaved
// (one 16-byte texel per voxel: 8 loads per lookup instead of 32).
struct Noise3 {
    std::vector<std::array<float, 4>> texels;
    int n = 0, nx = 0, ny = 0, nz = 0;
    int mx = -1, my = -1, mz = -1; // n - 1 for power-of-two sizes, else -1
    double inv_tile = 0;
    bool ok() const { return n > 0; }
    void init(const Field3D* f, double tile) {
        if (!f) return;
        n = std::min(4, f->channels());
        nx = f->nx();
        ny = f->ny();
        nz = f->nz();
        mx = is_pow2(nx) ? nx - 1 : -1;
        my = is_pow2(ny) ? ny - 1 : -1;
        mz = is_pow2(nz) ? nz - 1 : -1;
        texels.resize(size_t(nx) * size_t(ny) * size_t(nz));
        for (int c = 0; c < 4; ++c) {
            auto ch = f->channel(std::min(c, n - 1));
            for (size_t i = 0; i < texels.size(); ++i) texels[i][size_t(c)] = ch[i];
        }
        inv_tile = 1.0 / tile;
    }
    ATLAS_LAYER_INLINE void sample(double x, double y, double z, float out[4]) const {
        int x0, x1, y0, y1, z0, z1;
        float tx, ty, tz;
        wrap_axis(x * inv_tile * nx, nx, mx, x0, x1, tx);
        wrap_axis(y * inv_tile * ny, ny, my, y0, y1, ty);
        wrap_axis(z * inv_tile * nz, nz, mz, z0, z1, tz);
        const size_t sy = size_t(nx), sz = size_t(nx) * size_t(ny);
        const std::array<float, 4>* t = texels.data();
        const size_t r0 = size_t(z0) * sz + size_t(y0) * sy, r1 = size_t(z0) * sz + size_t(y1) * sy;
        const size_t r2 = size_t(z1) * sz + size_t(y0) * sy, r3 = size_t(z1) * sz + size_t(y1) * sy;
        const auto& a0 = t[r0 + size_t(x0)];
        const auto& a1 = t[r0 + size_t(x1)];
        const auto& b0 = t[r1 + size_t(x0)];
        const auto& b1 = t[r1 + size_t(x1)];
        const auto& c0 = t[r2 + size_t(x0)];
        const auto& c1 = t[r2 + size_t(x1)];
        const auto& d0 = t[r3 + size_t(x0)];
        const auto& d1 = t[r3 + size_t(x1)];
        for (size_t c = 0; c < 4; ++c) {
            const float a = a0[c] + (a1[c] - a0[c]) * tx;
            const float b = b0[c] + (b1[c] - b0[c]) * tx;
            const float cc = c0[c] + (c1[c] - c0[c]) * tx;
            const float d = d0[c] + (d1[c] - d0[c]) * tx;
            const float ab = a + (b - a) * ty, cd = cc + (d - cc) * ty;
            out[c] = ab + (cd - ab) * tz;
        }
    }
};

inline int channel_of(const Field2D& f, const char* name) { return f.find_channel(name); }

// The weather at one map position.
struct Column {
    double coverage = 0, type = 0, top_type = 0, bottom_type = 0, min_h = 0, max_h = 0, precip = 0;
};

// bottom(bottom_type, f) * top(top_type, f) from the LUT's two channels,
// end-aligned texels (ndf/profile_lut): texel i at type i / (W - 1); the
// height axis is shared by both lookups.
ATLAS_LAYER_INLINE double profile_split(const Field2D& lut, const float* bottom, const float* top, double bottom_type, double top_type, double f) {
    const int w = lut.width(), h = lut.height();
    Bilinear b;
    axis_clamp(0.5 + detail::saturate(f) * (h - 1), h, b.y0, b.y1, b.ty);
    axis_clamp(0.5 + detail::saturate(bottom_type) * (w - 1), w, b.x0, b.x1, b.tx);
    const double lo = lerp2(bottom, w, b);
    if (!(lo > 0)) return 0;
    axis_clamp(0.5 + detail::saturate(top_type) * (w - 1), w, b.x0, b.x1, b.tx);
    return lo * lerp2(top, w, b);
}

// Everything the march reads, prepared once per render.
class LayerModel {
public:
    // mean_table: also build mean_density's table (a few milliseconds; the
    // renderer's sky light reads it, density queries and framing do not).
    explicit LayerModel(const LayerScene& s, bool mean_table = false) : s_(s), ndf_(*s.ndf), lut_(*s.profile_lut) {
        const int cc = channel_of(ndf_, "coverage"), cmin = channel_of(ndf_, "min_height"), cmax = channel_of(ndf_, "max_height");
        const int ct = channel_of(ndf_, "type"), ctt = channel_of(ndf_, "top_type"), cbt = channel_of(ndf_, "bottom_type");
        const int cp = channel_of(ndf_, "precipitation");
        ch_cov_ = ndf_.channel(cc).data();
        ch_min_ = ndf_.channel(cmin).data();
        ch_max_ = ndf_.channel(cmax).data();
        ch_type_ = ct >= 0 ? ndf_.channel(ct).data() : nullptr;
        ch_top_ = ctt >= 0 ? ndf_.channel(ctt).data() : ch_type_;
        ch_bot_ = cbt >= 0 ? ndf_.channel(cbt).data() : ch_type_;
        ch_precip_ = cp >= 0 ? ndf_.channel(cp).data() : nullptr;
        // Interleaved copy: coverage, min, max, type, top type, bottom type, precipitation.
        texels_.resize(size_t(ndf_.width()) * size_t(ndf_.height()));
        for (size_t i = 0; i < texels_.size(); ++i)
            texels_[i] = {ch_cov_[i], ch_min_[i], ch_max_[i], ch_type_ ? ch_type_[i] : 0.0f, ch_top_ ? ch_top_[i] : 0.0f,
                          ch_bot_ ? ch_bot_[i] : 0.0f, ch_precip_ ? ch_precip_[i] : 0.0f, 0.0f};
        lut_bottom_ = lut_.channel(lut_.find_channel("bottom")).data();
        lut_top_ = lut_.channel(lut_.find_channel("top")).data();
        const Box2d& b = ndf_.bounds();
        origin_ = {{b.min[0], b.min[1]}};
        size_ = {{b.max[0] - b.min[0], b.max[1] - b.min[1]}};
        inv_texel_ = {{ndf_.width() / size_[0], ndf_.height() / size_[1]}};
        map_mask_ = {is_pow2(ndf_.width()) ? ndf_.width() - 1 : -1, is_pow2(ndf_.height()) ? ndf_.height() - 1 : -1};
        centre_ = {{0.5 * (b.min[0] + b.max[0]), 0.5 * (b.min[1] + b.max[1]), -s.earth_radius}};
        bottom_ = std::numeric_limits<double>::infinity();
        top_ = -bottom_;
        auto cov = ndf_.channel(cc), mn = ndf_.channel(cmin), mx = ndf_.channel(cmax);
        for (size_t i = 0; i < cov.size(); ++i) {
            if (!(cov[i] > 0) || !(mx[i] > mn[i])) continue;
            bottom_ = std::min(bottom_, double(mn[i]));
            top_ = std::max(top_, double(mx[i]));
            any_cloud_ = true;
        }
        if (!any_cloud_) bottom_ = top_ = 0;
        set_top_ = top_;
        if (ch_precip_) {
            auto p = ndf_.channel(cp);
            precipitation_ = std::any_of(p.begin(), p.end(), [](float v) { return v > 0; });
        }
        base_.init(s.base_noise.get(), s.base_tile);
        if (base_.ok()) build_coverage_table(*s.base_noise, mean_table);
        detail_.init(s.detail_noise.get(), s.detail_tile);
        if (s.curl) {
            curl_ = s.curl.get();
            curl_r_ = curl_->channel(0).data();
            curl_g_ = curl_->channel(std::min(1, curl_->channels() - 1)).data();
            curl_mask_ = {is_pow2(curl_->width()) ? curl_->width() - 1 : -1, is_pow2(curl_->height()) ? curl_->height() - 1 : -1};
        }
        const double w = std::hypot(s.wind[0], s.wind[1]);
        rise_ = 0.1 * w * s.time; // the noise's upward scroll (clouds seem to grow)
        wind_dir_ = w > 0 ? Vec2d{{s.wind[0] / w, s.wind[1] / w}} : Vec2d{{1, 0}};
        map_shift_ = {{s.wind[0] * s.time, s.wind[1] * s.time}};
        if (s.envelope.cone_map) {
            cone_ = s.envelope.cone_map.get();
            const int ca = cone_->find_channel("apex_height"), cr = cone_->find_channel("cone_ratio");
            cone_apex_ = cone_->channel(ca).data();
            cone_ratio_ = cone_->channel(cr).data();
        }
        if (s.envelope.distance_map) dist_ = s.envelope.distance_map.get();
        if (s.vortex_table) {
            const Field2D& t = *s.vortex_table;
            const int ci = t.find_channel("inner"), co = t.find_channel("outer"), cs = t.find_channel("speed"), ce = t.find_channel("overlap_end");
            const int ck = t.find_channel("skew");
            bool skewed = false;
            std::vector<Ring> rings;
            for (int i = 0; i < t.width(); ++i) {
                const double k = ck >= 0 ? double(t.at(ck, i, 0)) : 0.0;
                skewed = skewed || k != 0;
                rings.push_back({t.at(ci, i, 0), t.at(co, i, 0), t.at(cs, i, 0), t.at(ce, i, 0), k});
            }
            // At time 0 without skew the rings turn nothing: no rings (same bytes as none).
            if (s.time != 0 || skewed) rings_ = std::move(rings);
            const Box2d& tb = t.bounds();
            vortex_centre_ = {{0.5 * (tb.min[0] + tb.max[0]), 0.5 * (tb.min[1] + tb.max[1])}};
        }
        if (s.anvil) {
            const Field2D& a = *s.anvil;
            const int c = std::max(0, a.find_channel("anvil_bias"));
            auto ch = a.channel(c);
            if (std::any_of(ch.begin(), ch.end(), [](float v) { return v > 0; })) {
                anvil_ = &a;
                anvil_ch_ = ch.data();
                const Box2d& ab = a.bounds();
                anvil_origin_ = {{ab.min[0], ab.min[1]}};
                anvil_inv_ = {{a.width() / (ab.max[0] - ab.min[0]), a.height() / (ab.max[1] - ab.min[1])}};
                const int cl = a.find_channel("anvil_lift");
                if (cl >= 0) {
                    auto lift = a.channel(cl);
                    double most = 0;
                    for (size_t i = 0; i < lift.size(); ++i)
                        if (ch[i] > 0) most = std::max(most, double(lift[i]));
                    if (most > 0) {
                        anvil_lift_ch_ = lift.data();
                        max_lift_ = most;
                        if (any_cloud_) top_ += most; // the anvil rises above the set's tops, at most this far
                    }
                }
            }
        }
    }
    bool has_anvil() const { return anvil_ != nullptr; }
    bool has_vortex() const { return !rings_.empty(); }

    // Vortex rings (000, "MDR Vortex Field"): the noise's sample positions turn about the
    // storm's centre, each ring at its own speed; the map itself (coverage, heights) does
    // not turn, so the storm keeps its shape and its billows swirl. Where two rings overlap
    // the noise is sampled at both turns and the samples interpolated, as 000 does:
    // interpolating the angle instead winds the noise into a tighter spiral every second.
    struct Turns {
        double angle[2] = {0, 0};
        double w = 0; // weight of angle[1]; 0: one sample
    };
    Turns vortex_turns(double r, double phi) const {
        Turns t;
        const size_t n = rings_.size();
        for (size_t i = 0; i < n; ++i) {
            const Ring& g = rings_[i];
            if (r < g.inner) break;
            const double a = g.speed * s_.time + g.skew * phi;
            if (r < g.outer) {
                t.angle[0] = a;
                // Inside ring i: the previous ring's overlap band reaches in.
                if (i > 0 && r < rings_[i - 1].overlap_end) {
                    const Ring& pr = rings_[i - 1];
                    t.angle[0] = pr.speed * s_.time + pr.skew * phi;
                    t.angle[1] = a;
                    t.w = (r - pr.outer) / std::max(1e-9, pr.overlap_end - pr.outer);
                }
                return t;
            }
            if (i + 1 == n && r < g.overlap_end) { // the outermost ring fades into the still sky
                t.angle[0] = a;
                t.w = (r - g.outer) / std::max(1e-9, g.overlap_end - g.outer);
                return t;
            }
        }
        return t;
    }
    // The noise's (x, y) for p at altitude h: up to two turned positions and the weight of
    // the second. The storm's centre moves with the map (the wind scrolls both).
    struct NoiseXY {
        double x[2], y[2];
        double w = 0;
    };
    NoiseXY noise_xy(const Vec3d& p, double h) const {
        NoiseXY q{{p[0], p[0]}, {p[1], p[1]}, 0};
        if (rings_.empty()) return q;
        const double cx = vortex_centre_[0] + map_shift_[0], cy = vortex_centre_[1] + map_shift_[1];
        const double dx = p[0] - cx, dy = p[1] - cy;
        const double phi = set_top_ > bottom_ ? detail::saturate((h - bottom_) / (set_top_ - bottom_)) : 0.0;
        const Turns t = vortex_turns(std::hypot(dx, dy), phi);
        for (int k = 0; k < 2; ++k) {
            const double a = -t.angle[k];
            if (a == 0) continue;
            const double c = std::cos(a), sn = std::sin(a);
            q.x[k] = cx + c * dx - sn * dy;
            q.y[k] = cy + sn * dx + c * dy;
        }
        q.w = t.w;
        return q;
    }
    // A noise texture's four channels at the (one or two) positions xy(k) gives, blended.
    template <class Sample>
    static void blended(const NoiseXY& q, Sample&& sample, float n[4]) {
        sample(0, n);
        if (q.w == 0) return;
        float m[4];
        sample(1, m);
        for (int c = 0; c < 4; ++c) n[c] = float(n[c] + (m[c] - n[c]) * q.w);
    }

    const Vec3d& centre() const { return centre_; }
    double bottom() const { return bottom_; }
    double top() const { return top_; }
    bool any_cloud() const { return any_cloud_; }
    bool precipitation() const { return precipitation_; }
    bool has_base() const { return base_.ok(); }
    bool has_detail() const { return detail_.ok(); }
    // The detail noise's texel in world metres along its finest axis (the
    // march reads it 1.3x faster than the base), infinite without detail.
    double detail_texel() const {
        if (!detail_.ok()) return std::numeric_limits<double>::infinity();
        return 1.0 / (detail_.inv_tile * 1.3 * std::max({detail_.nx, detail_.ny, detail_.nz}));
    }
    bool has_curl() const { return curl_ != nullptr; }
    bool has_cone() const { return cone_ != nullptr; }
    bool has_distance() const { return dist_ != nullptr && max_lift_ == 0; } // a lifted anvil is not in the distance map

    double altitude(const Vec3d& p) const { return length(p - centre_) - s_.earth_radius; }

    // The weather at world (x, y); false outside an Empty-edged map.
    bool column(double x, double y, Column& c) const {
        double u = (x - map_shift_[0] - origin_[0]) * inv_texel_[0], v = (y - map_shift_[1] - origin_[1]) * inv_texel_[1];
        const int nx = ndf_.width(), ny = ndf_.height();
        Bilinear b;
        if (s_.edge == MapEdge::Empty && (u < 0 || v < 0 || u > nx || v > ny)) return false;
        if (s_.edge == MapEdge::Wrap) {
            wrap_axis(u, nx, map_mask_[0], b.x0, b.x1, b.tx);
            wrap_axis(v, ny, map_mask_[1], b.y0, b.y1, b.ty);
        } else {
            axis_clamp(u, nx, b.x0, b.x1, b.tx);
            axis_clamp(v, ny, b.y0, b.y1, b.ty);
        }
        // One 32-byte texel per corner (channels interleaved at construction).
        const std::array<float, 8>* t = texels_.data();
        const auto& a0 = t[size_t(b.y0) * size_t(nx) + size_t(b.x0)];
        const auto& a1 = t[size_t(b.y0) * size_t(nx) + size_t(b.x1)];
        const auto& b0 = t[size_t(b.y1) * size_t(nx) + size_t(b.x0)];
        const auto& b1 = t[size_t(b.y1) * size_t(nx) + size_t(b.x1)];
        auto at = [&](size_t k) {
            const float lo = a0[k] + (a1[k] - a0[k]) * b.tx, hi = b0[k] + (b1[k] - b0[k]) * b.tx;
            return double(lo + (hi - lo) * b.ty);
        };
        c.coverage = at(0);
        if (!(c.coverage > 0)) return false;
        // Heights are weighted by coverage: a clear texel's heights say
        // nothing, and lerping them in drew a slanted sheet tens of metres
        // thin from a cloud's texel to its clear neighbour (the superstorm's
        // 1.5-4 km cumulus beside the sheet's clear 11 km edge: a veil that
        // the march hit at random, bench/grain.sh). Equal heights come out
        // exactly as they went in.
        const float w[4] = {(1 - b.tx) * (1 - b.ty) * a0[0], b.tx * (1 - b.ty) * a1[0], (1 - b.tx) * b.ty * b0[0], b.tx * b.ty * b1[0]};
        const float wsum = w[0] + w[1] + w[2] + w[3];
        auto weighted = [&](size_t k) {
            if (!(wsum > 0)) return at(k);
            const float r = a0[k];
            return double(r + (w[1] * (a1[k] - r) + w[2] * (b0[k] - r) + w[3] * (b1[k] - r)) / wsum);
        };
        c.min_h = weighted(1);
        c.max_h = weighted(2);
        c.type = at(3);
        c.top_type = at(4);
        c.bottom_type = at(5);
        c.precip = detail::saturate(at(6));
        return c.max_h > c.min_h;
    }

    // Coverage is the probability of cloud (ndf_set.h): the threshold the
    // coverage remap uses is the (1 - coverage) quantile of the dilated base
    // shape over the noise texture, so coverage c leaves a fraction c of a
    // full-profile column cloudy (the noise's own range, 0.39..0.97 for the
    // HZD Perlin-Worley, would otherwise turn coverage 0.3 into overcast).
    // kQuantiles + 1 evenly spaced quantiles of sorted values (the nearest rank).
    static auto quantiles_of(const std::vector<float>& sorted) {
        std::array<double, kQuantiles + 1> q{};
        for (int k = 0; k <= kQuantiles; ++k) q[size_t(k)] = sorted[std::min(sorted.size() - 1, size_t(double(k) / kQuantiles * double(sorted.size() - 1) + 0.5))];
        return q;
    }
    // HZD's coverage remap of a base value: remap(base, thr, 1, 0, 1) * coverage,
    // in [0, 1] (0 where thr >= 1: no cloud).
    static double coverage_shaped(double base, double thr, double coverage) {
        return thr < 1.0 ? std::clamp((base - thr) / (1.0 - thr) * coverage, 0.0, 1.0) : 0.0;
    }
    void build_coverage_table(const Field3D& n, bool mean_table) {
        const int c = n.channels();
        auto r = n.channel(0), g = n.channel(std::min(1, c - 1)), b = n.channel(std::min(2, c - 1)), a = n.channel(std::min(3, c - 1));
        std::vector<float> v;
        const size_t stride = std::max<size_t>(1, r.size() / 65536);
        for (size_t i = 0; i < r.size(); i += stride) v.push_back(float(ndf::dilated_base(r[i], g[i], b[i], a[i])));
        std::sort(v.begin(), v.end());
        quantile_ = quantiles_of(v);
        equalised_ = true;
        base_max_ = quantile_[kQuantiles];
        if (!mean_table) return;
        // mean_density's table: the shape's mean over the values the march
        // reads, at (profile, coverage) on a (kMeanSteps + 1)^2 grid. Those are
        // trilinear between texels, a narrower spread than the texels' own:
        // means over the texels' quantiles came out 5-20 % high in the tails
        // against brute force (LayerMeanDensity test). So the spread is taken
        // from 32^3 points at hashed offsets inside their cells of the tile.
        std::vector<float> read;
        const int cells = 32;
        read.reserve(size_t(cells) * cells * cells);
        const double tile = 1.0 / base_.inv_tile;
        for (int z = 0; z < cells; ++z)
            for (int y = 0; y < cells; ++y)
                for (int x = 0; x < cells; ++x) {
                    const int id = x + cells * (y + cells * z);
                    auto at = [&](int axis, int k) { return (k + hash_to_unit(hash_coords(0x6d65616eu, id, axis))) * tile / cells; };
                    float t[4];
                    base_.sample(at(0, x), at(1, y), at(2, z), t);
                    read.push_back(float(ndf::dilated_base(t[0], t[1], t[2], t[3])));
                }
        std::sort(read.begin(), read.end());
        const std::array<double, kQuantiles + 1> spread = quantiles_of(read);
        mean_shape_.assign(size_t(kMeanSteps + 1) * size_t(kMeanSteps + 1), 0.0);
        for (int j = 0; j <= kMeanSteps; ++j) {
            const double cov = double(j) / kMeanSteps, thr = coverage_threshold(cov);
            for (int i = 0; i <= kMeanSteps; ++i) {
                const double profile = double(i) / kMeanSteps;
                double sum = 0;
                for (double q : spread) sum += coverage_shaped(q * profile, thr, cov);
                mean_shape_[size_t(j) * (kMeanSteps + 1) + size_t(i)] = sum / double(spread.size());
            }
        }
    }
    // The base value above which a fraction `coverage` of the texture lies.
    double coverage_threshold(double coverage) const {
        if (!equalised_) return 1.0 - coverage;
        const double u = (1.0 - detail::saturate(coverage)) * kQuantiles;
        const int i = std::min(kQuantiles - 1, int(u));
        return quantile_[size_t(i)] + (quantile_[size_t(i + 1)] - quantile_[size_t(i)]) * (u - i);
    }

    // Where p (altitude h) sits in its column: the map's weather with the
    // anvil's spread and lift applied, the height fraction f, the profile and
    // the coverage threshold. False where no cloud can be (outside the
    // column, a zero profile, or a profile that even the noise's largest
    // value leaves under the threshold).
    struct ShapeInputs {
        Column c;
        double f = 0, profile = 0, thr = 1;
    };
    bool shape_inputs(const Vec3d& p, double h, ShapeInputs& in) const {
        Column& c = in.c;
        if (!column(p[0], p[1], c)) return false;
        if (h <= c.min_h) return false;
        double bias = 0;
        if (anvil_ && (h > c.min_h + 0.7 * (c.max_h - c.min_h) || h >= c.max_h)) {
            Bilinear b;
            axis_clamp((p[0] - map_shift_[0] - anvil_origin_[0]) * anvil_inv_[0], anvil_->width(), b.x0, b.x1, b.tx);
            axis_clamp((p[1] - map_shift_[1] - anvil_origin_[1]) * anvil_inv_[1], anvil_->height(), b.y0, b.y1, b.ty);
            bias = detail::saturate(lerp2(anvil_ch_, anvil_->width(), b));
            // The anvil rises: where bias > 0 the column's top is max_height + lift.
            if (anvil_lift_ch_ && bias > 0) c.max_h += std::max(0.0f, lerp2(anvil_lift_ch_, anvil_->width(), b));
        }
        if (h >= c.max_h) return false;
        const double f = (h - c.min_h) / (c.max_h - c.min_h);
        if (bias > 0 && f > 0.7) {
            // HZD's anvil bias: the top of the column spreads.
            c.coverage = std::pow(c.coverage, detail::remap(f, 0.7, 0.8, 1.0, 1.0 - 0.5 * bias));
        }
        in.f = f;
        in.profile = profile_split(lut_, lut_bottom_, lut_top_, c.bottom_type, c.top_type, f);
        if (!(in.profile > 0)) return false;
        in.thr = coverage_threshold(c.coverage);
        // The base is at most the texture's largest value: skip the lookup
        // where even that stays under the coverage threshold.
        return in.profile * base_max_ > in.thr;
    }

    // The cheap shape's density at p averaged over the base noise (the mean
    // of density(p, h, false) over the noise texture's values, from a table
    // over profile and coverage): the weather map's smooth part without the
    // noise's texture. The sky light's occlusion reads it (LayerIntegrator::
    // sky_depth): sky light comes from the whole hemisphere, and a vertical
    // line through the noise drew every billow's column as a streak toward
    // the zenith on an overcast's underside seen from below.
    double mean_density(const Vec3d& p, double h) const {
        if (!base_.ok()) return density(p, h, false); // no noise: the shape is its mean
        need(!mean_shape_.empty(), "internal: mean_density without its table (LayerModel(scene, true))");
        ShapeInputs in;
        if (!shape_inputs(p, h, in)) return 0;
        const double u = detail::saturate(in.profile) * kMeanSteps, v = detail::saturate(in.c.coverage) * kMeanSteps;
        const int i = std::min(kMeanSteps - 1, int(u)), j = std::min(kMeanSteps - 1, int(v));
        const double tu = u - i, tv = v - j;
        auto at = [&](int a, int b) { return mean_shape_[size_t(b) * (kMeanSteps + 1) + size_t(a)]; };
        const double lo = at(i, j) + (at(i + 1, j) - at(i, j)) * tu, hi = at(i, j + 1) + (at(i + 1, j + 1) - at(i, j + 1)) * tu;
        return (lo + (hi - lo) * tv) * s_.density_scale;
    }

    // Density at p (altitude h). full = false: the cheap base shape only
    // (HZD's "cheap" sample). shape_out: the base shape with coverage (the
    // sample's profile for ambient and multiple scattering).
    double density(const Vec3d& p, double h, bool full, Column* col_out = nullptr, double* shape_out = nullptr) const {
        ShapeInputs in;
        if (!shape_inputs(p, h, in)) return 0;
        const Column& c = in.c;
        const double f = in.f, profile = in.profile, thr = in.thr;
        // Wind: tops pushed downwind, the noise scrolled (detail faster, a
        // little upward: clouds seem to grow).
        const double skew = f * s_.cloud_top_offset;
        const NoiseXY xy = noise_xy(p, h);
        auto qx = [&](int k) { return xy.x[k] + wind_dir_[0] * skew - s_.wind[0] * s_.time; };
        auto qy = [&](int k) { return xy.y[k] + wind_dir_[1] * skew - s_.wind[1] * s_.time; };
        const double qz = h - rise_;
        double base = 1;
        if (base_.ok()) {
            float n[4];
            blended(xy, [&](int k, float* out) { base_.sample(qx(k), qy(k), qz, out); }, n);
            base = ndf::dilated_base(n[0], n[1], n[2], n[3]);
        }
        base *= profile;
        // Coverage grows the shape and scales its density: HZD's
        // remap(base, 1 - coverage, 1, 0, 1) * coverage with the equalised threshold.
        const double shaped = coverage_shaped(base, thr, c.coverage);
        if (!(shaped > 0)) return 0;
        if (col_out) *col_out = c;
        if (shape_out) *shape_out = shaped;
        if (!full || !detail_.ok()) return shaped * s_.density_scale;
        const double dz = qz * 1.3;
        float n[4];
        blended(xy, [&](int k, float* out) {
            double dx = qx(k) * 1.3, dy = qy(k) * 1.3; // detail moves faster than the base (detail_texel)
            if (curl_) {
                // Turbulence at the cloud base: curl-distorted detail coordinates.
                Bilinear b;
                wrap_axis(dx / s_.curl_tile * curl_->width(), curl_->width(), curl_mask_[0], b.x0, b.x1, b.tx);
                wrap_axis(dy / s_.curl_tile * curl_->height(), curl_->height(), curl_mask_[1], b.y0, b.y1, b.ty);
                const double amount = s_.curl_amount * (1.0 - f);
                dx += (2.0 * lerp2(curl_r_, curl_->width(), b) - 1.0) * amount;
                dy += (2.0 * lerp2(curl_g_, curl_->width(), b) - 1.0) * amount;
            }
            detail_.sample(dx, dy, dz, out);
        }, n);
        const double high_fbm = ndf::worley_fbm(n[0], n[1], n[2]);
        // Wispy (FBM) at the base to billowy (inverted) above 10 % height.
        const double mod = high_fbm + ((1.0 - high_fbm) - high_fbm) * detail::saturate(f * 10.0);
        const double final_density = detail::saturate(detail::remap_unclamped(shaped, mod * s_.erosion, 1.0, 0.0, 1.0));
        return final_density * s_.density_scale;
    }

    // Envelope: a distance along the unit ray that surely holds no cloud, 0
    // when none is known. p at altitude h.
    double skip_distance(const Vec3d& p, const Vec3d& d, double h) const {
        double best = 0;
        const double u = (p[0] - map_shift_[0] - origin_[0]) / size_[0], v = (p[1] - map_shift_[1] - origin_[1]) / size_[1];
        if (!(u >= 0 && u <= 1 && v >= 0 && v <= 1)) return 0; // the maps cover one tile
        // Never jump past the map tile (its neighbours are other data).
        double to_edge = std::numeric_limits<double>::infinity();
        for (int a = 0; a < 2; ++a) {
            const double lo = origin_[a] + map_shift_[a], hi = lo + size_[a];
            if (d[a] > 1e-12) to_edge = std::min(to_edge, (hi - p[a]) / d[a]);
            else if (d[a] < -1e-12) to_edge = std::min(to_edge, (lo - p[a]) / d[a]);
        }
        if (cone_) {
            Bilinear b;
            axis_clamp(u * cone_->width(), cone_->width(), b.x0, b.x1, b.tx);
            axis_clamp(v * cone_->height(), cone_->height(), b.y0, b.y1, b.ty);
            // A lifted anvil raises every top by at most max_lift_: so are the apexes.
            const double apex = lerp2(cone_apex_, cone_->width(), b) + max_lift_, c = lerp2(cone_ratio_, cone_->width(), b);
            if (h > apex && c > 0) {
                const double hl = std::hypot(d[0], d[1]);
                const double denom = hl - c * d[2];
                const double s = denom > 1e-12 ? c * (h - apex) / denom : std::numeric_limits<double>::infinity();
                best = std::max(best, s);
            }
        }
        if (dist_) {
            const Box3d& bb = dist_->bounds();
            const Vec3d vs = dist_->voxel_size();
            const double z = h;
            if (z >= bb.min[2] && z <= bb.max[2]) {
                // Trilinear distance minus a voxel diagonal: interpolation
                // and voxel-centre solids are each off by less than that.
                const double fx = u * dist_->nx() - 0.5, fy = v * dist_->ny() - 0.5, fz = (z - bb.min[2]) / vs[2] - 0.5;
                auto cl = [](double t, int n) { return std::clamp(t, 0.0, double(n - 1)); };
                const double cx = cl(fx, dist_->nx()), cy = cl(fy, dist_->ny()), cz = cl(fz, dist_->nz());
                const int x0 = int(cx), y0 = int(cy), z0 = int(cz);
                const int x1 = std::min(x0 + 1, dist_->nx() - 1), y1 = std::min(y0 + 1, dist_->ny() - 1), z1 = std::min(z0 + 1, dist_->nz() - 1);
                const double tx = cx - x0, ty = cy - y0, tz = cz - z0;
                auto at = [&](int x, int y, int zz) { return double(dist_->at(0, x, y, zz)); };
                const double c00 = at(x0, y0, z0) + (at(x1, y0, z0) - at(x0, y0, z0)) * tx;
                const double c10 = at(x0, y1, z0) + (at(x1, y1, z0) - at(x0, y1, z0)) * tx;
                const double c01 = at(x0, y0, z1) + (at(x1, y0, z1) - at(x0, y0, z1)) * tx;
                const double c11 = at(x0, y1, z1) + (at(x1, y1, z1) - at(x0, y1, z1)) * tx;
                const double c0 = c00 + (c10 - c00) * ty, c1 = c01 + (c11 - c01) * ty;
                const double dd = c0 + (c1 - c0) * tz - length(vs);
                best = std::max(best, dd);
            }
        }
        return std::min(best, to_edge);
    }

private:
    const LayerScene& s_;
    const Field2D& ndf_;
    const Field2D& lut_;
    const float *ch_cov_, *ch_min_, *ch_max_, *ch_type_, *ch_top_, *ch_bot_, *ch_precip_;
    const float *lut_bottom_, *lut_top_;
    std::vector<std::array<float, 8>> texels_;
    Vec2d origin_, size_, inv_texel_;
    std::array<int, 2> map_mask_{{-1, -1}}, curl_mask_{{-1, -1}};
    Vec3d centre_;
    double bottom_ = 0, top_ = 0, set_top_ = 0; // set_top_: without the anvil's lift
    bool any_cloud_ = false, precipitation_ = false;
    Noise3 base_, detail_;
    const Field2D* curl_ = nullptr;
    const float *curl_r_ = nullptr, *curl_g_ = nullptr;
    Vec2d wind_dir_, map_shift_;
    double rise_ = 0;
    const Field2D* cone_ = nullptr;
    const float *cone_apex_ = nullptr, *cone_ratio_ = nullptr;
    const Field3D* dist_ = nullptr;
    static constexpr int kQuantiles = 256;
    std::array<double, kQuantiles + 1> quantile_{};
    bool equalised_ = false;
    static constexpr int kMeanSteps = 64;
    std::vector<double> mean_shape_; // mean_density's table, (kMeanSteps + 1)^2, coverage-major
    double base_max_ = 1; // largest dilated base value (1 without noise)
    struct Ring {
        double inner, outer, speed, overlap_end, skew;
    };
    std::vector<Ring> rings_;
    Vec2d vortex_centre_{{0, 0}};
    const Field2D* anvil_ = nullptr;
    const float* anvil_ch_ = nullptr;
    const float* anvil_lift_ch_ = nullptr;
    double max_lift_ = 0;
    Vec2d anvil_origin_{{0, 0}}, anvil_inv_{{1, 1}};
};

} // namespace atlas::render::layer_detail

// Domain warp, curve, threshold and composite (blur is in blur.cpp).
#include "atlas/ndf/operators.h"
#include "atlas/ndf/ndf_set.h"

#include "atlas/core/error.h"
#include "atlas/core/field_math.h"
#include "atlas/core/parallel.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace atlas::ndf {

namespace {
Field2D like(const Field2D& in, const MemoryBudget* budget) {
    return Field2D(in.resolution(), in.channels(), in.bounds(), in.channel_names(), budget);
}
} // namespace

namespace {
// Field2D::sample_texel's arithmetic, inlined with the texel size computed
// once per call instead of per sample (same operations, same bytes).
struct Taps {
    int i0, i1;
    float t;
};
inline int fix_index(int i, int n, WrapMode wrap) {
    if (wrap == WrapMode::Wrap) {
        i %= n;
        return i < 0 ? i + n : i;
    }
    return i < 0 ? 0 : (i >= n ? n - 1 : i);
}
inline Taps taps(double u, int n, WrapMode wrap) {
    double f = u - 0.5;
    if (!std::isfinite(f)) f = 0.0;
    double fl = std::floor(f);
    const float t = float(f - fl);
    fl = std::clamp(fl, -1e9, 1e9);
    const int base = int(fl);
    return {fix_index(base, n, wrap), fix_index(base + 1, n, wrap), t};
}
} // namespace

Field2D domain_warp(const Field2D& in, const Field2D& warp, double amount, WrapMode wrap, const MemoryBudget* budget) {
    return domain_warp(in, warp, amount, wrap, WarpWindow{in.bounds(), in.resolution(), 0, 0}, budget);
}

Field2D domain_warp(const Field2D& in, const Field2D& warp, double amount, WrapMode wrap, const WarpWindow& window, const MemoryBudget* budget) {
    if (warp.resolution() != in.resolution()) throw Error("warp: the 'warp' input must have the resolution of 'in'");
    if (!std::isfinite(amount)) throw Error("warp: 'amount' must be finite");
    Field2D out = like(in, budget);
    const int cy = warp.channels() > 1 ? 1 : 0;
    const int w = in.width(), h = in.height();
    // Positions and taps are the whole grid's; a tap is read from the window,
    // clamped into it (for the whole grid a no-op).
    const Vec2d lo = window.bounds.min;
    const Vec2d s{{window.bounds.size()[0] / window.grid[0], window.bounds.size()[1] / window.grid[1]}};
    const int x0 = window.x0, y0 = window.y0;
    auto local = [](Taps t, int origin, int n) {
        return Taps{std::clamp(t.i0 - origin, 0, n - 1), std::clamp(t.i1 - origin, 0, n - 1), t.t};
    };
    const auto wx = warp.channel(0), wy = warp.channel(cy);
    parallel_for_index(h, [&](int y) { // rows are independent: the same bytes for any thread count
        const double py = lo[1] + (y0 + y + 0.5) * s[1];
        for (int x = 0; x < w; ++x) {
            const size_t i = in.index(x, y);
            const double px = lo[0] + (x0 + x + 0.5) * s[0];
            const double qx = px + amount * (2.0 * wx[i] - 1.0), qy = py + amount * (2.0 * wy[i] - 1.0);
            const Taps tx = local(taps((qx - lo[0]) / s[0], window.grid[0], wrap), x0, w);
            const Taps ty = local(taps((qy - lo[1]) / s[1], window.grid[1], wrap), y0, h);
            const size_t r0 = size_t(ty.i0) * size_t(w), r1 = size_t(ty.i1) * size_t(w);
            for (int c = 0; c < in.channels(); ++c) {
                const float* ch = in.channel(c).data();
                const float a = lerp(ch[r0 + size_t(tx.i0)], ch[r0 + size_t(tx.i1)], tx.t);
                const float b = lerp(ch[r1 + size_t(tx.i0)], ch[r1 + size_t(tx.i1)], tx.t);
                out.channel(c)[i] = lerp(a, b, ty.t);
            }
        }
    });
    return out;
}

Curve::Curve(std::vector<Vec2d> points) : p_(std::move(points)) {
    if (p_.size() < 2) throw Error("curve: 'points' needs at least 2 control points");
    for (size_t i = 0; i < p_.size(); ++i) {
        if (!std::isfinite(p_[i][0]) || !std::isfinite(p_[i][1])) throw Error("curve: 'points' must be finite");
        if (i > 0 && !(p_[i][0] > p_[i - 1][0])) throw Error("curve: 'points' x values must be strictly increasing");
    }
    // Fritsch-Carlson monotone tangents.
    const size_t n = p_.size();
    std::vector<double> d(n - 1);
    for (size_t i = 0; i + 1 < n; ++i) d[i] = (p_[i + 1][1] - p_[i][1]) / (p_[i + 1][0] - p_[i][0]);
    m_.assign(n, 0.0);
    m_[0] = d[0];
    m_[n - 1] = d[n - 2];
    for (size_t i = 1; i + 1 < n; ++i) m_[i] = (d[i - 1] * d[i] <= 0) ? 0.0 : 0.5 * (d[i - 1] + d[i]);
    for (size_t i = 0; i + 1 < n; ++i) {
        if (d[i] == 0) { m_[i] = m_[i + 1] = 0; continue; }
        const double a = m_[i] / d[i], b = m_[i + 1] / d[i];
        const double s = a * a + b * b;
        if (s > 9) {
            const double t = 3.0 / std::sqrt(s);
            m_[i] = t * a * d[i];
            m_[i + 1] = t * b * d[i];
        }
    }
}

Curve Curve::parse(const std::string& text) {
    std::vector<Vec2d> pts;
    std::stringstream all(text);
    std::string entry;
    while (std::getline(all, entry, ';')) {
        std::istringstream in(entry);
        double x, y;
        if (!(in >> x)) continue;
        std::string rest;
        if (!(in >> y) || (in >> rest)) throw Error("curve: 'points' entries are 'x y' pairs separated by ';' (got '" + entry + "')");
        pts.push_back({{x, y}});
    }
    return Curve(std::move(pts));
}

double Curve::operator()(double x) const {
    if (std::isnan(x)) return p_.front()[1];
    if (x <= p_.front()[0]) return p_.front()[1];
    if (x >= p_.back()[0]) return p_.back()[1];
    const auto it = std::upper_bound(p_.begin(), p_.end(), x, [](double v, const Vec2d& p) { return v < p[0]; });
    const size_t i = size_t(it - p_.begin()) - 1;
    const double h = p_[i + 1][0] - p_[i][0];
    const double t = (x - p_[i][0]) / h;
    const double t2 = t * t, t3 = t2 * t;
    return (2 * t3 - 3 * t2 + 1) * p_[i][1] + (t3 - 2 * t2 + t) * h * m_[i] + (-2 * t3 + 3 * t2) * p_[i + 1][1] +
           (t3 - t2) * h * m_[i + 1];
}

Field2D apply_curve(const Field2D& in, const Curve& curve, const MemoryBudget* budget) {
    Field2D out = like(in, budget);
    for (int c = 0; c < in.channels(); ++c) {
        auto src = in.channel(c);
        auto dst = out.channel(c);
        parallel_for_each(src.size(), 4096, [&](size_t i) { dst[i] = float(curve(src[i])); });
    }
    return out;
}

Field2D threshold(const Field2D& in, double level, double width, const MemoryBudget* budget) {
    if (!std::isfinite(level)) throw Error("threshold: 'level' must be finite");
    if (!(width >= 0) || !std::isfinite(width)) throw Error("threshold: 'width' must be >= 0 and finite");
    Field2D out = like(in, budget);
    for (int c = 0; c < in.channels(); ++c) {
        auto src = in.channel(c);
        auto dst = out.channel(c);
        parallel_for_each(src.size(), 4096, [&](size_t i) {
            const double v = src[i];
            dst[i] = width > 0 ? float(smoothstep(level - 0.5 * width, level + 0.5 * width, v)) : (v >= level ? 1.0f : 0.0f);
        });
    }
    return out;
}

CompositeOp parse_composite_op(const std::string& name) {
    if (name == "add") return CompositeOp::Add;
    if (name == "multiply") return CompositeOp::Multiply;
    if (name == "max") return CompositeOp::Max;
    if (name == "min") return CompositeOp::Min;
    if (name == "over") return CompositeOp::Over;
    if (name == "lerp") return CompositeOp::Lerp;
    throw Error("composite: unknown 'mode' '" + name + "' (expected add, multiply, max, min, over, lerp)");
}

Field2D composite(const Field2D& a, const Field2D& b, const Field2D* mask, CompositeOp op, double opacity, const MemoryBudget* budget) {
    if (b.resolution() != a.resolution()) throw Error("composite: input 'b' must have the resolution of 'a'");
    if (b.channels() != a.channels() && b.channels() != 1) throw Error("composite: input 'b' must have a's channel count or 1 channel");
    if (mask && (mask->resolution() != a.resolution() || mask->channels() != 1))
        throw Error("composite: input 'mask' must have a's resolution and 1 channel");
    if (!std::isfinite(opacity)) throw Error("composite: 'opacity' must be finite");
    Field2D out = like(a, budget);
    for (int c = 0; c < a.channels(); ++c) {
        auto sa = a.channel(c);
        auto sb = b.channel(b.channels() == 1 ? 0 : c);
        auto dst = out.channel(c);
        parallel_for_each(sa.size(), 4096, [&](size_t i) {
            const float x = sa[i], y = sb[i];
            float r = y;
            switch (op) {
            case CompositeOp::Add: r = x + y; break;
            case CompositeOp::Multiply: r = x * y; break;
            case CompositeOp::Max: r = std::max(x, y); break;
            case CompositeOp::Min: r = std::min(x, y); break;
            case CompositeOp::Over: r = y + x * (1.0f - y); break;
            case CompositeOp::Lerp: r = y; break;
            }
            const float t = float(opacity) * (mask ? mask->channel(0)[i] : 1.0f);
            dst[i] = t == 1.0f ? r : (t == 0.0f ? x : lerp(x, r, t));
        });
    }
    return out;
}

} // namespace atlas::ndf

// ndf/warp: domain warp of a map by another map.
#include "atlas/ndf/operators.h"
#include "ndf/ndf_params.h"
#include "atlas/core/parallel.h"

#include <algorithm>
#include <cmath>

namespace {
using namespace atlas;
using namespace atlas::ndf_nodes;

// A tiled cook's halo: the largest offset |amount| in texels, + 1 for the
// bilinear tap, + 1 for rounding.
int warp_halo(const NodeParams& p, const TileGrid& g) {
    const double sx = g.bounds.size()[0] / g.res[0], sy = g.bounds.size()[1] / g.res[1];
    const double texels = std::ceil(std::abs(p.get_float("amount")) / std::min(sx, sy)) + 2;
    return int(std::min(texels, double(std::max(g.res[0], g.res[1]))));
}

void declare(NodeDeclaration& d) {
    d.doc("Domain warp: out(p) = in(p + amount * (2 * warp(p) - 1)), bilinear; warp channel 0 moves x, channel 1 (or 0) moves y. "
          "Tiles (tileable: false) with a halo of |amount| in texels + 2; a tiled cook then requires every warp value in [0, 1].");
    d.input("in", PortType::Field2D, "map to warp");
    d.input("warp", PortType::Field2D, "offsets in [0, 1] (0.5 = none), the resolution of `in`");
    d.tiling(TileRule::with_grid_halo(warp_halo,
                                      [](const NodeParams& p) -> std::string {
                                          if (p.get_bool("tileable"))
                                              return "tileable: true wraps lookups around the map, which no local halo covers";
                                          if (!std::isfinite(p.get_float("amount"))) return "'amount' is not finite";
                                          return "";
                                      })
                 .with_window());
    d.output("out", PortType::Field2D, "warped map");
    d.param_float("amount", 1000).with_unit("m").describe("largest offset");
    d.param_bool("tileable", true).describe("wrap lookups around the map (keeps tileable maps tileable); else clamp");
}

// ndf::domain_warp's arithmetic (the same operations, so the same bytes), on
// a window [x0, x0 + w) x [y0, y0 + h) of a W x H grid with origin `lo` and
// texel size `s`: positions and taps are the whole grid's; a tap is then
// read from the window (clamped into it: only texels whose results the tiled
// cook discards, in the halo band, can reach beyond it).
Field2D warp_window(const Field2D& in, const Field2D& warp, double amount, WrapMode wrap, Vec2d lo, Vec2d s, Vec2i grid, int x0, int y0,
                    const MemoryBudget* budget) {
    if (!std::isfinite(amount)) throw Error("warp: 'amount' must be finite");
    Field2D out(in.resolution(), in.channels(), in.bounds(), in.channel_names(), budget);
    const int cy = warp.channels() > 1 ? 1 : 0;
    const int w = in.width(), h = in.height();
    const auto wx = warp.channel(0), wy = warp.channel(cy);
    auto fix = [&](int i, int n) {
        if (wrap == WrapMode::Wrap) {
            i %= n;
            return i < 0 ? i + n : i;
        }
        return i < 0 ? 0 : (i >= n ? n - 1 : i);
    };
    struct Taps {
        int i0, i1;
        float t;
    };
    auto taps = [&](double u, int n, int origin, int local) {
        double f = u - 0.5;
        if (!std::isfinite(f)) f = 0.0;
        double fl = std::floor(f);
        const float t = float(f - fl);
        fl = std::clamp(fl, -1e9, 1e9);
        const int base = int(fl);
        return Taps{std::clamp(fix(base, n) - origin, 0, local - 1), std::clamp(fix(base + 1, n) - origin, 0, local - 1), t};
    };
    parallel_for_index(h, [&](int y) { // rows are independent: the same bytes for any thread count
        const double py = lo[1] + (y0 + y + 0.5) * s[1];
        for (int x = 0; x < w; ++x) {
            const size_t i = in.index(x, y);
            const double px = lo[0] + (x0 + x + 0.5) * s[0];
            const double qx = px + amount * (2.0 * wx[i] - 1.0), qy = py + amount * (2.0 * wy[i] - 1.0);
            const Taps tx = taps((qx - lo[0]) / s[0], grid[0], x0, w), ty = taps((qy - lo[1]) / s[1], grid[1], y0, h);
            const size_t r0 = size_t(ty.i0) * size_t(w), r1 = size_t(ty.i1) * size_t(w);
            for (int c = 0; c < in.channels(); ++c) {
                const float* ch = in.channel(c).data();
                const float a = atlas::lerp(ch[r0 + size_t(tx.i0)], ch[r0 + size_t(tx.i1)], tx.t);
                const float b = atlas::lerp(ch[r1 + size_t(tx.i0)], ch[r1 + size_t(tx.i1)], tx.t);
                out.channel(c)[i] = atlas::lerp(a, b, ty.t);
            }
        }
    });
    return out;
}

void cook(CookContext& ctx) {
    auto in = ctx.input_field2d("in");
    auto w = ctx.input_field2d("warp");
    if (w->resolution() != in->resolution()) ctx.fail("input 'warp' must have the resolution of 'in'");
    const double amount = ctx.get_float("amount");
    if (const TileWindow* win = ctx.window()) {
        // A tiled cook: `in` and `warp` are a crop of the whole grid. The halo
        // covers offsets up to |amount|, i.e. warp values in [0, 1].
        for (int c = 0; c < w->channels(); ++c) {
            const auto v = w->channel(c);
            for (size_t i = 0; i < v.size(); ++i)
                if (!(v[i] >= 0.0f && v[i] <= 1.0f))
                    ctx.fail("input 'warp' holds " + std::to_string(v[i]) + " at texel (" + std::to_string(win->x0 + int(i % size_t(w->width()))) +
                             ", " + std::to_string(win->y0 + int(i / size_t(w->width()))) + ") of channel " + std::to_string(c) +
                             ", outside [0, 1]: its offset exceeds 'amount', the halo of a tiled cook");
        }
        const Vec2d lo = win->grid.bounds.min;
        const Vec2d s{{win->grid.bounds.size()[0] / win->grid.res[0], win->grid.bounds.size()[1] / win->grid.res[1]}};
        ctx.set_output("out", out2d(warp_window(*in, *w, amount, wrap_mode(ctx), lo, s, win->grid.res, win->x0, win->y0, &ctx.budget())));
        return;
    }
    ctx.set_output("out", out2d(ndf::domain_warp(*in, *w, amount, wrap_mode(ctx), &ctx.budget())));
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "ndf/warp", .version = 1, .declare = declare, .cook = cook});
}

// ndf/warp: domain warp of a map by another map.
#include "atlas/ndf/operators.h"
#include "ndf/ndf_params.h"

#include <algorithm>
#include <cmath>

namespace {
using namespace atlas;
using namespace atlas::ndf_nodes;

// A tiled cook's halo: the largest offset |amount| in texels, + 1 for the
// bilinear tap, + 1 for rounding. Tileable, the lookups wrap around the whole map:
// the halo is the whole grid, so each tile warps the whole map (exact, as a wrap
// across the world must be; the cook says the halo is wider than a tile).
int warp_halo(const NodeParams& p, const TileGrid& g) {
    if (p.get_bool("tileable")) return std::max(g.res[0], g.res[1]);
    const double sx = g.bounds.size()[0] / g.res[0], sy = g.bounds.size()[1] / g.res[1];
    const double texels = std::ceil(std::abs(p.get_float("amount")) / std::min(sx, sy)) + 2;
    return int(std::min(texels, double(std::max(g.res[0], g.res[1]))));
}

void declare(NodeDeclaration& d) {
    d.doc("Domain warp: out(p) = in(p + amount * (2 * warp(p) - 1)), bilinear; warp channel 0 moves x, channel 1 (or 0) moves y. "
          "Tiles with a halo of |amount| in texels + 2 (tileable: false; a tiled cook then requires every warp value in [0, 1]), or of the whole map "
          "(tileable: true: the lookups wrap around the world, not the tile).");
    d.input("in", PortType::Field2D, "map to warp");
    d.input("warp", PortType::Field2D, "offsets in [0, 1] (0.5 = none), the resolution of `in`");
    d.tiling(TileRule::with_grid_halo(warp_halo,
                                      [](const NodeParams& p) -> std::string {
                                          if (!std::isfinite(p.get_float("amount"))) return "'amount' is not finite";
                                          return "";
                                      })
                 .with_window());
    d.output("out", PortType::Field2D, "warped map");
    d.param_float("amount", 1000).with_unit("m").describe("largest offset");
    d.param_bool("tileable", true).describe("wrap lookups around the map (keeps tileable maps tileable); else clamp");
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
        const ndf::WarpWindow window{win->grid.bounds, win->grid.res, win->x0, win->y0};
        ctx.set_output("out", out2d(ndf::domain_warp(*in, *w, amount, wrap_mode(ctx), window, &ctx.budget())));
        return;
    }
    ctx.set_output("out", out2d(ndf::domain_warp(*in, *w, amount, wrap_mode(ctx), &ctx.budget())));
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "ndf/warp", .version = 1, .declare = declare, .cook = cook});
}

// ndf/blur: separable Gaussian blur.
#include "atlas/ndf/operators.h"
#include "ndf/ndf_params.h"

#include <algorithm>
#include <cmath>

namespace {
using namespace atlas;
using namespace atlas::ndf_nodes;

void declare(NodeDeclaration& d) {
    d.doc("Separable Gaussian blur of every channel; kernel radius ceil(3 sigma).");
    d.input("in", PortType::Field2D, "map");
    // Tileable, the blur wraps around the whole map: its halo is the whole grid, so each tile
    // blurs the whole map (exact, as a wrap across the world must be), else ceil(3 sigma).
    d.tiling(TileRule::with_grid_halo([](const NodeParams& p, const TileGrid& g) {
        const int h = int(std::ceil(3 * p.get_float("sigma")));
        return p.get_bool("tileable") ? std::max({h, g.res[0], g.res[1]}) : h;
    }));
    d.output("out", PortType::Field2D, "blurred map");
    d.param_float("sigma", 2.0).range(0, 4096).with_unit("texels").describe("standard deviation (0 copies)").follows_proxy(ProxyScale::CellLength);
    d.param_bool("tileable", true).describe("wrap around the edges (keeps tileable maps tileable); else clamp");
}

void cook(CookContext& ctx) {
    ctx.set_output("out", out2d(ndf::blur(*ctx.input_field2d("in"), ctx.get_float("sigma"), wrap_mode(ctx), &ctx.budget())));
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "ndf/blur", .version = 1, .declare = declare, .cook = cook});
}

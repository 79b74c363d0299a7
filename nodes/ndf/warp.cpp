// ndf/warp: domain warp of a map by another map.
#include "atlas/ndf/operators.h"
#include "ndf/ndf_params.h"

namespace {
using namespace atlas;
using namespace atlas::ndf_nodes;

void declare(NodeDeclaration& d) {
    d.doc("Domain warp: out(p) = in(p + amount * (2 * warp(p) - 1)), bilinear; warp channel 0 moves x, channel 1 (or 0) moves y.");
    d.input("in", PortType::Field2D, "map to warp");
    d.input("warp", PortType::Field2D, "offsets in [0, 1] (0.5 = none), the resolution of `in`");
    d.tiling(TileRule::none("it maps texels through the map's world bounds, which a cropped tile changes in the last bit (docs/scale.md)"));
    d.output("out", PortType::Field2D, "warped map");
    d.param_float("amount", 1000).with_unit("m").describe("largest offset");
    d.param_bool("tileable", true).describe("wrap lookups around the map (keeps tileable maps tileable); else clamp");
}

void cook(CookContext& ctx) {
    auto in = ctx.input_field2d("in");
    auto w = ctx.input_field2d("warp");
    if (w->resolution() != in->resolution()) ctx.fail("input 'warp' must have the resolution of 'in'");
    ctx.set_output("out", out2d(ndf::domain_warp(*in, *w, ctx.get_float("amount"), wrap_mode(ctx), &ctx.budget())));
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "ndf/warp", .version = 1, .declare = declare, .cook = cook});
}

// ndf/constant: a 2D map with one value everywhere.
#include "ndf/ndf_params.h"

namespace {
using namespace atlas;
using namespace atlas::ndf_nodes;

void declare(NodeDeclaration& d) {
    d.doc("A 1-channel 2D map over the world XY plane, every texel set to `value`.");
    d.tiling(TileRule::pointwise());
    d.output("out", PortType::Field2D, "the constant map");
    declare_map(d);
    d.param_float("value", 0.0).describe("value of every texel");
}

void cook(CookContext& ctx) {
    auto f = ctx.make_field2d(map_resolution(ctx), 1, map_bounds(ctx), {"value"});
    std::fill(f->channel(0).begin(), f->channel(0).end(), float(ctx.get_float("value")));
    ctx.set_output("out", Field2DPtr(f));
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "ndf/constant", .version = 1, .declare = declare, .cook = cook});
}

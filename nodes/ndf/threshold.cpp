// ndf/threshold: hard or smooth step.
#include "atlas/ndf/operators.h"
#include "ndf/ndf_params.h"

namespace {
using namespace atlas;
using namespace atlas::ndf_nodes;

void declare(NodeDeclaration& d) {
    d.doc("1 where the value is >= `level`, else 0; with `width` > 0 a smoothstep from level - width/2 to level + width/2.");
    d.input("in", PortType::Field2D, "map");
    d.tiling(TileRule::pointwise());
    d.output("out", PortType::Field2D, "mask");
    d.param_float("level", 0.5).describe("threshold");
    d.param_float("width", 0.0).range(0, 1e30).describe("smooth transition width (0: hard step)");
}

void cook(CookContext& ctx) {
    ctx.set_output("out", out2d(ndf::threshold(*ctx.input_field2d("in"), ctx.get_float("level"), ctx.get_float("width"), &ctx.budget())));
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "ndf/threshold", .version = 1, .declare = declare, .cook = cook});
}

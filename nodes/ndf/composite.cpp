// ndf/composite: combine two maps, optionally through a mask.
#include "atlas/ndf/operators.h"
#include "ndf/ndf_params.h"

namespace {
using namespace atlas;
using namespace atlas::ndf_nodes;

void declare(NodeDeclaration& d) {
    d.doc("result = a + (op(a, b) - a) * opacity * mask. add, multiply, max, min; over = b + a (1 - b) (b as its own coverage); "
          "lerp = b (the mask picks between a and b).");
    d.input("a", PortType::Field2D, "base map");
    d.input("b", PortType::Field2D, "layer (a's channel count or 1 channel, a's resolution)");
    d.input("mask", PortType::Field2D, "optional 1-channel weight (default 1)").optional = true;
    d.tiling(TileRule::pointwise());
    d.output("out", PortType::Field2D, "composited map");
    d.param_enum("mode", {"add", "multiply", "max", "min", "over", "lerp"}, "max").describe("how b combines with a");
    d.param_float("opacity", 1.0).describe("global weight of the layer");
}

void cook(CookContext& ctx) {
    auto a = ctx.input_field2d("a");
    auto b = ctx.input_field2d("b");
    Field2DPtr m = ctx.has_input("mask") ? ctx.input_field2d("mask") : nullptr;
    if (b->resolution() != a->resolution()) ctx.fail("input 'b' must have the resolution of 'a'");
    if (m && m->resolution() != a->resolution()) ctx.fail("input 'mask' must have the resolution of 'a'");
    ctx.set_output("out", out2d(ndf::composite(*a, *b, m.get(), ndf::parse_composite_op(ctx.get_string("mode")), ctx.get_float("opacity"),
                                               &ctx.budget())));
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "ndf/composite", .version = 1, .declare = declare, .cook = cook});
}

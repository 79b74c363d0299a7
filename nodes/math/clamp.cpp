// math/clamp: clamp every value into [min, max] (saturate with the defaults).
#include "atlas/core/field_math.h"
#include "atlas/graph/node.h"

namespace {
using namespace atlas;

void declare(NodeDeclaration& d) {
    d.doc("Clamps every value into [min, max]; NaN becomes min. With the defaults this is saturate (0..1).");
    d.input("in", PortType::Field, "field to clamp");
    d.tiling(TileRule::pointwise());
    d.output("out", PortType::Field, "clamped field");
    d.param_float("min", 0.0).describe("lower bound");
    d.param_float("max", 1.0).describe("upper bound (must be >= min)");
}

void cook(CookContext& ctx) {
    if (ctx.get_float("min") > ctx.get_float("max")) ctx.fail("parameter 'min' is greater than 'max'");
    ctx.set_output("out", field_clamp(ctx.input("in"), ctx.get_float("min"), ctx.get_float("max"), &ctx.budget()));
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "math/clamp", .version = 1, .declare = declare, .cook = cook});
}

// math/remap: fit a value range onto another (the Nubis remap()).
#include "atlas/core/field_math.h"
#include "atlas/graph/node.h"

namespace {
using namespace atlas;

void declare(NodeDeclaration& d) {
    d.doc("Fit range: maps [in_min, in_max] linearly onto [out_min, out_max], optionally clamping to the output range.");
    d.input("in", PortType::Field, "field to remap");
    d.tiling(TileRule::pointwise());
    d.output("out", PortType::Field, "remapped field");
    d.param_float("in_min", 0.0).describe("input value mapped to out_min");
    d.param_float("in_max", 1.0).describe("input value mapped to out_max (equal to in_min: everything maps to out_min)");
    d.param_float("out_min", 0.0).describe("output at in_min");
    d.param_float("out_max", 1.0).describe("output at in_max");
    d.param_bool("clamp", true).describe("clamp the result into the output range");
}

void cook(CookContext& ctx) {
    if (ctx.get_float("in_min") == ctx.get_float("in_max"))
        ctx.warn("in_min equals in_max: every value maps to out_min");
    ctx.set_output("out", field_remap(ctx.input("in"), ctx.get_float("in_min"), ctx.get_float("in_max"), ctx.get_float("out_min"),
                                      ctx.get_float("out_max"), ctx.get_bool("clamp"), &ctx.budget()));
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "math/remap", .version = 1, .declare = declare, .cook = cook});
}

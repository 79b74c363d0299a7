// math/lerp: a + (b - a) * t.
#include "atlas/core/field_math.h"
#include "atlas/graph/node.h"

namespace {
using namespace atlas;

void declare(NodeDeclaration& d) {
    d.doc("Linear blend a + (b - a) * t of two fields; t is a mask field (1 or N channels) or the constant `t`.");
    d.input("a", PortType::Field, "field at t = 0");
    d.input("b", PortType::Field, "field at t = 1, same resolution as a");
    d.input("t", PortType::Field, "blend mask; when unconnected the parameter `t` is used").optional = true;
    d.tiling(TileRule::pointwise());
    d.output("out", PortType::Field, "the blend");
    d.param_float("t", 0.5).describe("constant blend factor when input t is unconnected (values outside 0..1 extrapolate)");
}

void cook(CookContext& ctx) {
    Value t = ctx.has_input("t") ? ctx.input("t") : Value{};
    ctx.set_output("out", field_lerp(ctx.input("a"), ctx.input("b"), t, ctx.get_float("t"), &ctx.budget()));
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "math/lerp", .version = 1, .declare = declare, .cook = cook});
}

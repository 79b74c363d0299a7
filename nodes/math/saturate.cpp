// math/saturate: clamp into [0, 1], the shader idiom.
#include "atlas/core/field_math.h"
#include "atlas/graph/node.h"

namespace {
using namespace atlas;

void declare(NodeDeclaration& d) {
    d.doc("Clamps every value into [0, 1] (HLSL saturate); NaN becomes 0.");
    d.input("in", PortType::Field, "field to saturate");
    d.tiling(TileRule::pointwise());
    d.output("out", PortType::Field, "values in [0, 1]");
}

void cook(CookContext& ctx) { ctx.set_output("out", field_clamp(ctx.input("in"), 0.0, 1.0, &ctx.budget())); }
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "math/saturate", .version = 1, .declare = declare, .cook = cook});
}

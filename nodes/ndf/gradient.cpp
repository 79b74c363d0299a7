// ndf/gradient: linear or radial ramp.
#include "atlas/ndf/generators.h"
#include "ndf/ndf_params.h"

namespace {
using namespace atlas;
using namespace atlas::ndf_nodes;

void declare(NodeDeclaration& d) {
    d.doc("A ramp in [0, 1]: linear (0 at `start`, 1 at `end`, clamped) or radial (1 at `center`, 0 at `radius` and beyond).");
    d.tiling(TileRule::pointwise());
    d.output("out", PortType::Field2D, "the gradient (1 channel)");
    declare_map(d);
    d.param_enum("mode", {"linear", "radial"}, "linear").describe("ramp shape");
    d.param_float2("start", {{0, 0}}).with_unit("m").describe("linear: world point where the ramp is 0");
    d.param_float2("end", {{60000, 0}}).with_unit("m").describe("linear: world point where the ramp is 1");
    d.param_float2("center", {{30000, 30000}}).with_unit("m").describe("radial: centre (value 1)");
    d.param_float("radius", 30000).with_unit("m").describe("radial: distance where the ramp reaches 0 (> 0)");
}

void cook(CookContext& ctx) {
    const Vec2i res = map_resolution(ctx);
    const Box2d box = map_bounds(ctx);
    if (ctx.get_string("mode") == "radial") {
        if (!(ctx.get_float("radius") > 0)) ctx.fail("'radius' must be > 0");
        ctx.set_output("out", out2d(ndf::gradient_radial(res, box, ctx.get_float2("center"), ctx.get_float("radius"), &ctx.budget())));
    } else {
        if (ctx.get_float2("start") == ctx.get_float2("end")) ctx.fail("'end' must differ from 'start'");
        ctx.set_output("out", out2d(ndf::gradient_linear(res, box, ctx.get_float2("start"), ctx.get_float2("end"), &ctx.budget())));
    }
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "ndf/gradient", .version = 1, .declare = declare, .cook = cook});
}

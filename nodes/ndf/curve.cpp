// ndf/curve: spline lookup of every texel.
#include "atlas/ndf/operators.h"
#include "ndf/ndf_params.h"

#include <optional>

namespace {
using namespace atlas;
using namespace atlas::ndf_nodes;

void declare(NodeDeclaration& d) {
    d.doc("Maps every value through a monotone cubic spline (Fritsch-Carlson: no overshoot) through `points`; constant beyond the ends.");
    d.input("in", PortType::Field2D, "map");
    d.tiling(TileRule::pointwise());
    d.output("out", PortType::Field2D, "curved map");
    d.param_string("points", "0 0; 0.5 0.5; 1 1").describe("control points 'x y; x y; ...', x strictly increasing");
}

void cook(CookContext& ctx) {
    std::optional<ndf::Curve> c;
    try {
        c.emplace(ndf::Curve::parse(ctx.get_string("points")));
    } catch (const Error& e) {
        ctx.fail(e.what());
    }
    ctx.set_output("out", out2d(ndf::apply_curve(*ctx.input_field2d("in"), *c, &ctx.budget())));
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "ndf/curve", .version = 1, .declare = declare, .cook = cook});
}

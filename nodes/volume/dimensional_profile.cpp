// volume/dimensional_profile: the 0..1 gradient from the cloud surface inward.
#include "atlas/volume/nvdf.h"
#include "atlas/graph/node.h"

namespace {
using namespace atlas;

void declare(NodeDeclaration& d) {
    d.doc("Dimensional profile from a signed distance field: saturate(-sdf / depth) ^ exponent - 0 at and outside the "
          "surface, 1 at `depth` metres inside and deeper.");
    d.input("sdf", PortType::Field3D, "signed distance, metres, negative inside");
    d.output("out", PortType::Field3D, "channel 'dimensional_profile', 0..1");
    d.tiling(TileRule::pointwise());
    d.param_float("depth", 64).range(1e-6, 1e9).with_unit("m").describe("depth inside the surface where the profile reaches 1");
    d.param_float("exponent", 1).range(1e-3, 1e3).describe("shape of the ramp (1 = linear)");
}

void cook(CookContext& ctx) {
    volume::DimensionalProfileOptions o;
    o.depth = ctx.get_float("depth");
    o.exponent = ctx.get_float("exponent");
    ctx.set_output("out", Field3DPtr(std::make_shared<Field3D>(volume::dimensional_profile(*ctx.input_field3d("sdf"), o, &ctx.budget()))));
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "volume/dimensional_profile", .version = 1, .declare = declare, .cook = cook});
}

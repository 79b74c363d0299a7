// volume/projection: a top-down opacity preview of a density volume.
#include "atlas/graph/node.h"
#include "atlas/volume/projection.h"

namespace {
using namespace atlas;

void declare(NodeDeclaration& d) {
    d.doc("Top-down preview: opacity 1 - exp(-extinction x sum of density x voxel height) along z, a 2D field.");
    d.input("in", PortType::Field3D, "density");
    d.output("out", PortType::Field2D, "channel 'opacity', 0..1");
    d.tiling(TileRule::pointwise()); // column by column
    d.param_float("extinction", 0.01).range(1e-9, 1e6).with_unit("1/m").describe("extinction per unit density");
    d.param_int("channel", 0).range(0, 255).describe("density channel");
}

void cook(CookContext& ctx) {
    ctx.set_output("out", Field2DPtr(std::make_shared<Field2D>(
                              volume::project_density(*ctx.input_field3d("in"), ctx.get_float("extinction"), int(ctx.get_int("channel"))))));
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "volume/projection", .version = 1, .declare = declare, .cook = cook});
}

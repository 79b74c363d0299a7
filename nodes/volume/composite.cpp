// volume/composite: frankenclouding - a cloud into the world grid.
#include "atlas/volume/edit.h"
#include "atlas/graph/node.h"

namespace {
using namespace atlas;

void declare(NodeDeclaration& d) {
    d.doc("Composites `cloud` (sampled trilinearly at the world's voxel centres, empty outside its grid, times opacity) into "
          "`world`: max, add, over (c + w (1 - saturate(c))) or subtract (max(w - c, 0)).");
    d.input("world", PortType::Field3D, "the world grid");
    d.input("cloud", PortType::Field3D, "the cloud (any grid)");
    // The world tiles; the cloud, on its own grid, is passed whole and sampled at the whole grid's positions.
    d.tiling(TileRule::pointwise().with_window().whole_input("cloud"));
    d.output("out", PortType::Field3D, "the world with the cloud");
    d.param_enum("op", {"max", "add", "over", "subtract"}, "max").describe("composite operation");
    d.param_float("opacity", 1).range(0, 1e6).describe("multiplies the cloud");
    d.param_int("world_channel", 0).range(0, 255).describe("world channel written");
    d.param_int("cloud_channel", 0).range(0, 255).describe("cloud channel read");
}

void cook(CookContext& ctx) {
    const GridFrame frame = ctx.frame(*ctx.input_field3d("world"));
    ctx.set_output("out", Field3DPtr(std::make_shared<Field3D>(volume::composite(
                              *ctx.input_field3d("world"), *ctx.input_field3d("cloud"), volume::parse_composite_op(ctx.get_string("op")),
                              ctx.get_float("opacity"), int(ctx.get_int("world_channel")), int(ctx.get_int("cloud_channel")), &ctx.budget(), &frame))));
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "volume/composite", .version = 1, .declare = declare, .cook = cook});
}

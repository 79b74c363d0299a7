// volume/world: the empty world grid clouds are composited into.
#include "grid_params.h"

namespace {
using namespace atlas;

void declare(NodeDeclaration& d) {
    d.doc("An empty (zero) density grid over the world; the default is the Nubis cloudscape, 4 km x 4 km x 512 m at 8 m voxels (512x512x64).");
    d.tiling(TileRule::pointwise());
    d.output("out", PortType::Field3D, "zero density, channel 'density'");
    volume_nodes::declare_grid(d);
}

void cook(CookContext& ctx) {
    ctx.set_output("out", Field3DPtr(ctx.make_field3d(ctx.get_int3("resolution"), 1, volume_nodes::grid_bounds(ctx), {"density"})));
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "volume/world", .version = 1, .declare = declare, .cook = cook});
}

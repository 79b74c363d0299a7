// volume/world: the empty world grid clouds are composited into.
#include "grid_params.h"

namespace {
using namespace atlas;

void declare(NodeDeclaration& d) {
    d.doc("An empty (zero) density grid over the world; the default is the Nubis cloudscape, 4 km x 4 km x 512 m at 8 m voxels (512x512x64).");
    d.tiling(TileRule::pointwise().windowed([](const NodeParams& p) -> std::optional<TileGrid> { return grid_nodes::tile_grid(p); }));
    d.output("out", PortType::Field3D, "zero density, channel 'density'");
    volume_nodes::declare_grid(d);
}

void cook(CookContext& ctx) {
    const Vec3i res = ctx.get_int3("resolution");
    const Box3d box = volume_nodes::grid_bounds(ctx);
    if (const TileWindow* w = ctx.window()) { // a tiled cook: just the tile's part of the world
        const XYWindow xy{w->x0, w->y0, w->x1, w->y1};
        ctx.set_output("out", Field3DPtr(ctx.make_field3d({{w->x1 - w->x0, w->y1 - w->y0, res[2]}}, 1, xy.bounds(res, box), {"density"})));
        return;
    }
    ctx.set_output("out", Field3DPtr(ctx.make_field3d(res, 1, box, {"density"})));
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "volume/world", .version = 1, .declare = declare, .cook = cook});
}

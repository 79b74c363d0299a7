// field/constant: a field filled with one value per channel.
#include "atlas/graph/node.h"
#include "common/grid.h"

namespace {
using namespace atlas;

void declare(NodeDeclaration& d) {
    d.doc("A 3D field of the given resolution and world bounds, every voxel set to `value`.");
    d.tiling(TileRule::pointwise().windowed([](const NodeParams& p) -> std::optional<TileGrid> { return grid_nodes::tile_grid(p); }));
    d.output("out", PortType::Field3D, "the constant field");
    grid_nodes::declare_grid(d, grid_nodes::kCoarseCloudscapeGrid);
    d.param_int("channels", 1).range(1, 16).describe("number of channels");
    d.param_float("value", 0.0).describe("value of every voxel in every channel");
}

void cook(CookContext& ctx) {
    Box3d box{ctx.get_float3("bounds_min"), ctx.get_float3("bounds_max")};
    if (!box.valid()) ctx.fail("bounds_max must be greater than bounds_min in every axis");
    Vec3i res = ctx.get_int3("resolution");
    if (const TileWindow* w = ctx.window()) { // a tiled cook's window of the grid
        res = {{w->size()[0], w->size()[1], res[2]}};
        box = {{{w->bounds().min[0], w->bounds().min[1], box.min[2]}}, {{w->bounds().max[0], w->bounds().max[1], box.max[2]}}};
    }
    auto f = ctx.make_field3d(res, int(ctx.get_int("channels")), box);
    const float v = float(ctx.get_float("value"));
    for (int c = 0; c < f->channels(); ++c) std::fill(f->channel(c).begin(), f->channel(c).end(), v);
    ctx.set_output("out", Field3DPtr(f));
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "field/constant", .version = 1, .declare = declare, .cook = cook});
}

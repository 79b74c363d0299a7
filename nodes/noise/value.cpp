// noise/value: tileable value-noise FBM filling a 3D field.
#include "atlas/graph/node.h"
#include "common/grid.h"
#include "atlas/noise/value_fbm.h"

namespace {
using namespace atlas;

void declare(NodeDeclaration& d) {
    d.doc("Tileable value noise with FBM octaves over a 3D field; values in [0, 1]. Tiles exactly every `period` lattice cells.");
    d.tiling(TileRule::pointwise());
    d.output("out", PortType::Field3D, "noise field (1 channel)");
    grid_nodes::declare_grid(d, grid_nodes::kCoarseCloudscapeGrid);
    d.param_int3("period", {{4, 4, 1}}).range(1, 4096).with_unit("cells").describe("lattice cells across the field per axis (the tiling period)");
    d.param_int("octaves", 3).range(1, 16).describe("FBM octaves; octave k has period * 2^k");
    d.param_float("gain", 0.5).range(0, 1).describe("amplitude ratio between octaves");
    d.param_int("seed", 0).range(0, 4294967295.0).describe("random seed");
}

void cook(CookContext& ctx) {
    Box3d box{ctx.get_float3("bounds_min"), ctx.get_float3("bounds_max")};
    if (!box.valid()) ctx.fail("bounds_max must be greater than bounds_min in every axis");
    const Vec3i res = ctx.get_int3("resolution");
    const Vec3i period = ctx.get_int3("period");
    const noise::ValueFbm fbm{.octaves = int(ctx.get_int("octaves")), .gain = ctx.get_float("gain"), .seed = uint32_t(ctx.get_int("seed"))};
    auto f = ctx.make_field3d(res, 1, box, {"density"});
    noise::fill_value_fbm(*f, 0, period, fbm);
    ctx.set_output("out", Field3DPtr(f));
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "noise/value", .version = 1, .declare = declare, .cook = cook});
}

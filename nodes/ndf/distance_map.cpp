// ndf/distance_map: 3D distance map above a height map.
#include "atlas/ndf/distance_map.h"
#include "ndf/ndf_params.h"

namespace {
using namespace atlas;
using namespace atlas::ndf_nodes;

void declare(NodeDeclaration& d) {
    d.tiling(TileRule::whole("each voxel's distance reads the whole height map"));
    d.doc("Exact Euclidean distance (m) from every voxel centre to the nearest voxel at or below the height map (GPU Gems 2 ch. 8 "
          "distance-step data), by linear-time separable sweeps.");
    d.input("in", PortType::Field2D, "height map");
    d.output("out", PortType::Field3D, "distance map (1 channel, metres)");
    d.param_string("channel", "max_height").describe("height channel name, or its index");
    d.param_int("layers", 32).range(1, 65536).describe("voxels along z");
    d.param_float("z_min", 0).with_unit("m").describe("bottom of the volume");
    d.param_float("z_max", 10000).with_unit("m").describe("top of the volume");
    d.param_float("max_distance", 1e5).with_unit("m").describe("cap (and the value when nothing is solid)");
}

void cook(CookContext& ctx) {
    auto in = ctx.input_field2d("in");
    const int c = channel_param(ctx, *in, "channel");
    if (!(ctx.get_float("z_max") > ctx.get_float("z_min"))) ctx.fail("'z_max' must be greater than 'z_min'");
    const uint64_t voxels = uint64_t(in->voxel_count()) * uint64_t(ctx.get_int("layers"));
    ctx.check_memory(voxels * (sizeof(float) + sizeof(double)), "the distance map");
    ctx.set_output("out", Field3DPtr(std::make_shared<const Field3D>(ndf::distance_map(*in, c, int(ctx.get_int("layers")), ctx.get_float("z_min"),
                                                                                        ctx.get_float("z_max"), ctx.get_float("max_distance"),
                                                                                        &ctx.budget()))));
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "ndf/distance_map", .version = 1, .declare = declare, .cook = cook});
}

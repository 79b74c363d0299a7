// volume/transform: move, rotate, scale and squash a cloud (trilinear resampling).
#include "atlas/volume/edit.h"
#include "atlas/graph/node.h"

namespace {
using namespace atlas;

void declare(NodeDeclaration& d) {
    d.tiling(TileRule::whole("it resamples the whole cloud (turned, squashed, moved)"));
    d.doc("p' = pivot + translate + Rz Ry Rx (scale * squash * (p - pivot)); squash s scales z by s and x, y by 1/sqrt(s) "
          "(volume kept). Resampled trilinearly onto the input's grid (or a new one); empty beyond the source.");
    d.input("in", PortType::Field3D, "cloud");
    d.output("out", PortType::Field3D, "moved cloud, all channels");
    d.param_float3("translate", {{0, 0, 0}}).with_unit("m").describe("offset");
    d.param_float3("rotate", {{0, 0, 0}}).with_unit("deg").describe("rotation about x, then y, then z");
    d.param_float3("scale", {{1, 1, 1}}).range(1e-6, 1e6).describe("scale per axis");
    d.param_float("squash", 1).range(1e-3, 1e3).describe("vertical squash (< 1 flattens), volume-preserving");
    d.param_float3("pivot", {{2048, 2048, 256}}).with_unit("m").describe("centre of rotation and scaling");
    d.param_bool("keep_grid", true).describe("output on the input's grid (else resolution/bounds below)");
    d.param_int3("resolution", {{512, 512, 64}}).range(1, 65536).with_unit("voxels").describe("output voxels when keep_grid is false").follows_proxy(ProxyScale::Cells);
    d.param_float3("bounds_min", {{0, 0, 0}}).with_unit("m").describe("output minimum corner when keep_grid is false");
    d.param_float3("bounds_max", {{4096, 4096, 512}}).with_unit("m").describe("output maximum corner when keep_grid is false");
}

void cook(CookContext& ctx) {
    auto in = ctx.input_field3d("in");
    volume::CloudTransform t;
    t.translate = ctx.get_float3("translate");
    t.rotate_deg = ctx.get_float3("rotate");
    t.scale = ctx.get_float3("scale");
    t.squash = ctx.get_float("squash");
    t.pivot = ctx.get_float3("pivot");
    const bool keep = ctx.get_bool("keep_grid");
    const Vec3i res = keep ? in->resolution() : ctx.get_int3("resolution");
    const Box3d box = keep ? in->bounds() : Box3d{ctx.get_float3("bounds_min"), ctx.get_float3("bounds_max")};
    if (!box.valid()) ctx.fail("bounds_max must be greater than bounds_min in every axis");
    ctx.check_memory(field_bytes(uint64_t(res[0]) * res[1] * res[2], in->channels()), "the transformed field");
    ctx.set_output("out", Field3DPtr(std::make_shared<Field3D>(volume::transform_field(*in, t, res, box, &ctx.budget()))));
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "volume/transform", .version = 1, .declare = declare, .cook = cook});
}

// volume/cutout: carve tunnels and caves with SDF shapes or another SDF (e.g. a mesh's).
#include "atlas/volume/edit.h"
#include "atlas/graph/node.h"

namespace {
using namespace atlas;

void declare(NodeDeclaration& d) {
    d.doc("Subtracts a shape (sphere, box, capsule) or, when `cutter` is connected, a signed distance field (such as "
          "volume/mesh_to_sdf's): density *= saturate(distance / edge); edge 0 cuts hard at the voxel centres.");
    d.input("in", PortType::Field3D, "density (all channels are cut)");
    d.input("cutter", PortType::Field3D, "optional signed distance (metres) of the cutting volume, any grid").optional = true;
    d.output("out", PortType::Field3D, "the carved density");
    d.tiling(TileRule::pointwise().with_window().whole_input("cutter"));
    d.param_enum("shape", {"sphere", "box", "capsule"}, "capsule").describe("cutting shape when no cutter is connected");
    d.param_float3("a", {{1024, 2048, 256}}).with_unit("m").describe("sphere/box centre, capsule first end");
    d.param_float3("b", {{3072, 2048, 256}}).with_unit("m").describe("capsule second end");
    d.param_float3("half_size", {{100, 100, 100}}).range(0, 1e9).with_unit("m").describe("box half extents");
    d.param_float("radius", 64).range(0, 1e9).with_unit("m").describe("sphere/capsule radius, box corner rounding");
    d.param_float("edge", 0).range(0, 1e9).with_unit("m").describe("soft edge width");
}

void cook(CookContext& ctx) {
    auto in = ctx.input_field3d("in");
    const GridFrame frame = ctx.frame(*in);
    const double edge = ctx.get_float("edge");
    if (ctx.has_input("cutter")) {
        ctx.set_output("out", Field3DPtr(std::make_shared<Field3D>(volume::cutout_density_by_sdf(*in, *ctx.input_field3d("cutter"), edge, &ctx.budget(), &frame))));
        return;
    }
    volume::Shape s;
    s.kind = volume::parse_shape_kind(ctx.get_string("shape"));
    s.a = ctx.get_float3("a");
    s.b = ctx.get_float3("b");
    s.half_size = ctx.get_float3("half_size");
    s.radius = ctx.get_float("radius");
    if (s.kind == volume::ShapeKind::Box) s.radius = std::min(s.radius, std::min({s.half_size[0], s.half_size[1], s.half_size[2]}));
    ctx.set_output("out", Field3DPtr(std::make_shared<Field3D>(volume::cutout_density(*in, s, edge, &ctx.budget(), &frame))));
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "volume/cutout", .version = 1, .declare = declare, .cook = cook});
}

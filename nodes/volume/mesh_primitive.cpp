// volume/mesh_primitive: a closed mesh built in the graph (box, sphere, torus).
#include "atlas/graph/node.h"
#include "atlas/volume/mesh_primitives.h"

namespace {
using namespace atlas;

void declare(NodeDeclaration& d) {
    d.doc("A closed, outward-facing triangle mesh: an axis-aligned box, a UV sphere or a torus around the z axis.");
    d.output("out", PortType::Mesh, "the mesh, metres");
    d.param_enum("shape", {"box", "sphere", "torus"}, "sphere").describe("which primitive");
    d.param_float3("center", {{2048, 2048, 256}}).with_unit("m").describe("centre");
    d.param_float3("half_size", {{200, 200, 100}}).range(1e-9, 1e9).with_unit("m").describe("box half extents");
    d.param_float("radius", 200).range(1e-9, 1e9).with_unit("m").describe("sphere radius; torus major radius");
    d.param_float("minor_radius", 80).range(1e-9, 1e9).with_unit("m").describe("torus tube radius");
    d.param_int("segments", 48).range(3, 4096).describe("sphere slices (stacks = half) / torus segments around z (tube: half)");
}

void cook(CookContext& ctx) {
    const std::string& s = ctx.get_string("shape");
    const Vec3d c = ctx.get_float3("center");
    const int n = int(ctx.get_int("segments"));
    Mesh m = s == "box"      ? volume::make_box_mesh(c, ctx.get_float3("half_size"))
             : s == "sphere" ? volume::make_sphere_mesh(c, ctx.get_float("radius"), std::max(2, n / 2), n)
                             : volume::make_torus_mesh(c, ctx.get_float("radius"), ctx.get_float("minor_radius"), n, std::max(3, n / 2));
    ctx.metric("triangles", double(m.triangles.size()));
    ctx.set_output("out", MeshPtr(std::make_shared<Mesh>(std::move(m))));
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "volume/mesh_primitive", .version = 1, .declare = declare, .cook = cook});
}

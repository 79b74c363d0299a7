// volume/blend: one NVDF set (or any field with an "sdf" channel) turning into another.
#include "atlas/graph/node.h"
#include "atlas/volume/nvdf.h"

namespace {
using namespace atlas;

void declare(NodeDeclaration& d) {
    d.doc("Blends two NVDF sets on one grid (volume/nvdf's vdb_set, or any fields with the same channels): every channel a (1 - t) + b t, "
          "except 'sdf', the distance to the union of both clouds (min) for 0 < t < 1, so that empty-space skipping never steps over the blend. "
          "Key `t` over the graph's time (docs/graph-format.md, \"Time\") to turn one cloudscape into another.");
    d.input("a", PortType::Field3D, "the set at t = 0");
    d.input("b", PortType::Field3D, "the set at t = 1, on a's grid with a's channels");
    d.output("out", PortType::Field3D, "the blend, a's channels");
    d.tiling(TileRule::pointwise());
    d.param_float("t", 0.5).range(0, 1).describe("blend amount: 0 is a, 1 is b");
}

void cook(CookContext& ctx) {
    const Field3DPtr a = ctx.input_field3d("a");
    const Field3DPtr b = ctx.input_field3d("b");
    try {
        ctx.set_output("out", Field3DPtr(std::make_shared<Field3D>(volume::blend_nvdf(*a, *b, ctx.get_float("t"), &ctx.budget()))));
    } catch (const Error& e) {
        ctx.fail(e.what());
    }
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "volume/blend", .version = 1, .declare = declare, .cook = cook});
}

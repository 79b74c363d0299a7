// volume/erode_noise: value erosion by fractal noise (the Nubis remap erosion).
#include "atlas/volume/edit.h"
#include "atlas/graph/node.h"

namespace {
using namespace atlas;

void declare(NodeDeclaration& d) {
    d.doc("Erodes density by noise as the Nubis sampler does: e = amount * n (n = fractal value noise in [0, 1]), "
          "d' = saturate((d - e) / (1 - e)). Thin density vanishes first; full density stays 1.");
    d.input("in", PortType::Field3D, "density");
    d.output("out", PortType::Field3D, "eroded density");
    d.tiling(TileRule::pointwise().with_window());
    d.param_float("amount", 0.5).range(0, 1).describe("erosion strength");
    d.param_float("frequency", 1.0 / 128.0).range(1e-9, 1e6).with_unit("1/m").describe("noise cells per metre (tiles on the bounds when frequency x extent is an integer)");
    d.param_int("octaves", 3).range(1, 12).describe("fractal octaves (lacunarity 2, gain 0.5)");
    d.param_int("seed", 1).range(0, 4294967295.0).describe("noise seed");
    d.param_int("channel", 0).range(0, 255).describe("channel eroded");
}

void cook(CookContext& ctx) {
    volume::ErosionOptions o;
    o.amount = ctx.get_float("amount");
    o.frequency = ctx.get_float("frequency");
    o.octaves = int(ctx.get_int("octaves"));
    o.seed = uint32_t(ctx.get_int("seed"));
    o.channel = int(ctx.get_int("channel"));
    auto in = ctx.input_field3d("in");
    const GridFrame frame = ctx.frame(*in);
    ctx.set_output("out", Field3DPtr(std::make_shared<Field3D>(volume::erode_by_noise(*in, o, &ctx.budget(), &frame))));
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "volume/erode_noise", .version = 1, .declare = declare, .cook = cook});
}

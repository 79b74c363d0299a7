// ndf/noise: tileable 2D value-noise FBM.
#include "atlas/ndf/generators.h"
#include "ndf/ndf_params.h"

namespace {
using namespace atlas;
using namespace atlas::ndf_nodes;

void declare(NodeDeclaration& d) {
    d.doc("Tileable 2D value-noise FBM in [0, 1] (atlas/noise value noise, z fixed); the map tiles exactly every `period` lattice cells.");
    d.tiling(TileRule::pointwise());
    d.output("out", PortType::Field2D, "noise map (1 channel)");
    declare_map(d);
    d.param_int2("period", {{8, 8}}).range(1, 4096).with_unit("cells").describe("lattice cells across the map per axis");
    d.param_int("octaves", 4).range(1, 16).describe("FBM octaves; octave k has period * 2^k");
    d.param_float("gain", 0.5).range(0, 1).describe("amplitude ratio between octaves");
    d.param_int("seed", 0).range(0, 4294967295.0).describe("random seed");
}

void cook(CookContext& ctx) {
    ctx.set_output("out", out2d(ndf::noise2d(map_resolution(ctx), map_bounds(ctx), ctx.get_int2("period"), int(ctx.get_int("octaves")),
                                             ctx.get_float("gain"), uint32_t(ctx.get_int("seed")), &ctx.budget())));
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "ndf/noise", .version = 1, .declare = declare, .cook = cook});
}

// ndf/cirrus_horizon: the cirrus horizon strip, mapped as a cylinder.
#include "atlas/ndf/cirrus.h"
#include "ndf/ndf_params.h"

namespace {
using namespace atlas;
using namespace atlas::ndf_nodes;

void declare(NodeDeclaration& d) {
    d.tiling(TileRule::whole("a horizon strip of its own"));
    d.doc("Cirrus horizon strip (FC6: 2048x128, mapped as a cylinder around the camera): x is the azimuth and tiles, row 0 is the "
          "horizon; layered stretched cirrus, denser toward the horizon, fading to 0 at the top (1 - smoothstep(fade_start, 1, v)).");
    d.output("out", PortType::Field2D, "strip (1 channel: cirrus_horizon)");
    d.param_int2("resolution", {{2048, 128}}).range(1, 16384).with_unit("texels").describe("texels around (x) and up (y)");
    d.param_int("cells_along", 24).range(1, 4096).with_unit("cells").describe("noise cells around the cylinder");
    d.param_float("cells_up", 4).range(1e-3, 1024).with_unit("cells").describe("noise cells over the strip's height");
    d.param_float("fade_start", 0.35).range(0, 0.999).describe("height fraction where the fade to the top starts");
    d.param_float("warp", 0.01).range(0, 1).describe("horizontal warp in strip lengths");
    d.param_int("seed", 0).range(0, 4294967295.0).describe("noise seed");
}

void cook(CookContext& ctx) {
    ndf::CirrusHorizonSpec s;
    s.resolution = ctx.get_int2("resolution");
    ctx.check_memory(field_bytes(uint64_t(s.resolution[0]) * uint64_t(s.resolution[1]), 1), "the horizon strip");
    s.cells_along = int(ctx.get_int("cells_along"));
    s.cells_up = ctx.get_float("cells_up");
    s.fade_start = ctx.get_float("fade_start");
    s.warp = ctx.get_float("warp");
    s.seed = uint32_t(ctx.get_int("seed"));
    ctx.set_output("out", out2d(ndf::cirrus_horizon(s, &ctx.budget())));
}
} // namespace

ATLAS_REGISTER_NODE(registry) { registry.add({.name = "ndf/cirrus_horizon", .version = 1, .declare = declare, .cook = cook}); }

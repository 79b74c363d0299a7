// ndf/cirrus: tileable cirrus texture, three looks in three channels.
#include "atlas/ndf/cirrus.h"
#include "ndf/ndf_params.h"

namespace {
using namespace atlas;
using namespace atlas::ndf_nodes;

void declare(NodeDeclaration& d) {
    d.tiling(TileRule::whole("a texture of its own (laid over the sky, not the map grid)"));
    d.doc(
        "Tileable cirrus texture for the sky hemisphere (FC6, HZD): channel cirrostratus (soft veil), cirrus (fibrous streaks), "
        "cirrocumulus (billowy puffs), opacities in [0, 1], from the noise library. Streaks run along an integer lattice "
        "direction so the texture still tiles. Bounds default to the unit square (a texture); set them to lay one tile over a world map.");
    d.output("out", PortType::Field2D, "cirrus texture (cirrostratus, cirrus, cirrocumulus)");
    d.param_int2("resolution", {{512, 512}}).range(1, 16384).with_unit("texels").describe("texels along x, y");
    d.param_int2("streak_direction", {{1, 0}}).range(-16, 16).describe("integer lattice vector the streaks run along (not 0,0)");
    d.param_int("period", 4).range(1, 256).with_unit("cells").describe("lattice cells across the texture (largest features)");
    d.param_int("stretch", 6).range(1, 64).describe("streak length / width");
    d.param_float("warp", 0.04).range(0, 1).describe("domain-warp displacement in texture widths");
    d.param_int("seed", 0).range(0, 4294967295.0).describe("noise seed");
    d.param_float2("bounds_min", {{0, 0}}).with_unit("m").describe("world box the texture covers (one tile): minimum corner");
    d.param_float2("bounds_max", {{1, 1}})
        .with_unit("m")
        .describe("maximum corner (e.g. the weather map's, to feed ndf/unity_cloud_layer)");
}

void cook(CookContext& ctx) {
    ndf::CirrusSpec s;
    s.resolution = ctx.get_int2("resolution");
    ctx.check_memory(field_bytes(uint64_t(s.resolution[0]) * uint64_t(s.resolution[1]), 3), "the cirrus texture");
    s.streak_direction = ctx.get_int2("streak_direction");
    if (s.streak_direction[0] == 0 && s.streak_direction[1] == 0) ctx.fail("'streak_direction' must not be (0, 0)");
    s.period = int(ctx.get_int("period"));
    s.stretch = int(ctx.get_int("stretch"));
    s.warp = ctx.get_float("warp");
    s.seed = uint32_t(ctx.get_int("seed"));
    s.bounds = map_bounds(ctx);
    ctx.set_output("out", out2d(ndf::cirrus_texture(s, &ctx.budget())));
}
} // namespace

ATLAS_REGISTER_NODE(registry) { registry.add({.name = "ndf/cirrus", .version = 1, .declare = declare, .cook = cook}); }

// ndf/cone_map: cone-step map of a height map (envelope method).
#include "atlas/ndf/cone_map.h"
#include "ndf/ndf_params.h"

namespace {
using namespace atlas;
using namespace atlas::ndf_nodes;

void declare(NodeDeclaration& d) {
    d.tiling(TileRule::whole("each texel's cone reads the whole height map"));
    d.doc("Conservative cone-step map of a height channel (box-column heightfield), by branch and bound over a max-mip pyramid "
          "(equal to brute force bit for bit). `robust` (default): channels apex_height (m) and cone_ratio, safe under bilinear "
          "filtering of both; otherwise 1 channel cone_ratio with the apex at the texel's own height (nearest sampling).");
    d.input("in", PortType::Field2D, "height map (e.g. an NDF set's max_height)");
    d.output("out", PortType::Field2D, "cone map");
    d.param_string("channel", "max_height").describe("height channel name, or its index");
    d.param_bool("robust", true).describe("bilinear-safe cones (apex = 5x5 max, cones valid over the bilinear footprint)");
    d.param_float("max_ratio", 1e4).range(1e-9, 1e30).describe("cap for cones that hit nothing (horizontal / vertical)");
}

void cook(CookContext& ctx) {
    auto in = ctx.input_field2d("in");
    const int c = channel_param(ctx, *in, "channel");
    const Vec2d vs = in->voxel_size();
    if (std::abs(vs[0] - vs[1]) > 1e-6 * std::max(vs[0], vs[1])) ctx.warn("texels are not square: cones use the smaller side (conservative)");
    ndf::ConeMapOptions opt;
    opt.texel_size = std::min(vs[0], vs[1]);
    opt.max_ratio = ctx.get_float("max_ratio");
    opt.robust = ctx.get_bool("robust");
    ctx.set_output("out", out2d(ndf::cone_map(*in, c, opt, &ctx.budget(), &ctx.progress_sink())));
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "ndf/cone_map", .version = 1, .declare = declare, .cook = cook});
}

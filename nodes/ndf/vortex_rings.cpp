// ndf/vortex_rings: the superstorm's nested vortex rings as a 2D map and a table.
#include "atlas/ndf/superstorm.h"
#include "ndf/ndf_params.h"

#include <sstream>

namespace {
using namespace atlas;
using namespace atlas::ndf_nodes;

void declare(NodeDeclaration& d) {
    d.tiling(TileRule::whole("a map-wide stencil"));
    d.doc("N nested vortex rings around a superstorm centre (rotation speed falling outward, overlapping, skewed). `map`: channels "
          "ring_index (-1 outside) and ring_blend (weight of the next ring in the overlap band). `table`: the sidecar the renderer "
          "reads, N x 1 texels, channels inner, outer (m), speed (rad/s), skew (rad), overlap_end (m, outer + overlap x width), "
          "world bounds = the square centre +- radius; write it as JSON (a `.json` output) or EXR.");
    d.output("map", PortType::Field2D, "ring-index / ring-blend map");
    d.output("table", PortType::Field2D, "ring table, one texel per ring (write as .json: the sidecar)");
    declare_map(d);
    d.param_float2("center", {{30000, 30000}}).with_unit("m").describe("storm centre");
    d.param_float("radius", 8000).with_unit("m").describe("outer radius of the last ring (> 0)");
    d.param_int("rings", 6).range(1, 256).describe("number of rings");
    d.param_string("ring_radii", "").describe("optional outer radii 'r1 r2 ...' (m, strictly increasing, <= radius); empty: even spacing");
    d.param_float("overlap", 0.25).range(0, 1).describe("overlap band past each ring, as a fraction of its width");
    d.param_float("speed", 0.05).with_unit("rad/s").describe("rotation speed of the innermost ring");
    d.param_float("skew", 0.3).with_unit("rad").describe("spiral skew of the outermost ring (0 for the innermost)");
}

void cook(CookContext& ctx) {
    std::vector<double> radii;
    std::istringstream in(ctx.get_string("ring_radii"));
    std::string tok;
    while (in >> tok) {
        try {
            radii.push_back(std::stod(tok));
        } catch (const std::exception&) {
            ctx.fail("'ring_radii': '" + tok + "' is not a number");
        }
    }
    std::vector<ndf::VortexRing> rings;
    try {
        rings = ndf::make_vortex_rings(ctx.get_float("radius"), int(ctx.get_int("rings")), radii, ctx.get_float("overlap"),
                                       ctx.get_float("speed"), ctx.get_float("skew"));
    } catch (const Error& e) {
        ctx.fail(e.what());
    }
    ctx.set_output("map", out2d(ndf::vortex_ring_map(map_resolution(ctx, 2), map_bounds(ctx), ctx.get_float2("center"), rings,
                                                     ctx.get_float("overlap"), &ctx.budget())));
    ctx.set_output("table", out2d(ndf::vortex_ring_table(ctx.get_float2("center"), ctx.get_float("radius"), ctx.get_float("overlap"), rings)));
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "ndf/vortex_rings", .version = 2, .declare = declare, .cook = cook});
}

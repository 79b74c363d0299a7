// ndf/shapes: ellipses, polygons and strokes painted from a list.
#include "atlas/ndf/generators.h"
#include "ndf/ndf_params.h"

namespace {
using namespace atlas;
using namespace atlas::ndf_nodes;

void declare(NodeDeclaration& d) {
    d.tiling(TileRule::whole("a map-wide stencil"));
    d.doc("Paints shapes over a zero map, each texel taking the max over shapes of value x weight (1 inside, a smoothstep "
          "falloff outside). Entries separated by ';': `ellipse CX CY RX RY VALUE FALLOFF`, `polygon VALUE FALLOFF X Y X Y X Y ...`, "
          "`stroke WIDTH VALUE FALLOFF X Y X Y ...` (metres).");
    d.output("out", PortType::Field2D, "the painted map (1 channel)");
    declare_map(d);
    d.param_string("shapes", "ellipse 30000 30000 10000 6000 1 4000").describe("the shape list (see above)");
}

void cook(CookContext& ctx) {
    std::vector<ndf::Shape> shapes;
    try {
        shapes = ndf::parse_shapes(ctx.get_string("shapes"));
    } catch (const Error& e) {
        ctx.fail(e.what());
    }
    if (shapes.empty()) ctx.warn("'shapes' is empty: the map is all zero");
    ctx.set_output("out", out2d(ndf::paint_shapes(map_resolution(ctx), map_bounds(ctx), shapes, &ctx.budget())));
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "ndf/shapes", .version = 1, .declare = declare, .cook = cook});
}

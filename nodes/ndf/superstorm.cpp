// ndf/superstorm: a mesocyclone stencil over an NDF set.
#include "atlas/ndf/superstorm.h"
#include "atlas/graph/option_params.h"
#include "ndf/ndf_params.h"

namespace {
using namespace atlas;
using namespace atlas::ndf_nodes;

void declare(NodeDeclaration& d) {
    d.tiling(TileRule::whole("a map-wide stencil"));
    d.doc("HFW superstorm stencil: raises coverage, type, top type and bottom type toward the centre, writes superstorm_coverage and "
          "blends min/max height toward the storm's by distorted radial gradients. Unchanged beyond `radius`; blend 0 is a no-op. "
          "Chain several to composite stencils. With `stretch` > 1 the footprint is a plume reaching stretch x radius downwind "
          "(`wind_direction`); `heights: sheet` makes it an anvil sheet instead: a flat top at max_height, the underside rising from "
          "min_height to the ragged rim, the map's own cloud in those columns replaced (chain the tower's radial stencil after it).");
    d.input("in", PortType::Field2D, "NDF set");
    d.output("out", PortType::Field2D, "NDF set with the stencil");
    d.param_float2("center", {{30000, 30000}}).with_unit("m").describe("stencil centre");
    // Every numeric option from the library's schema (one default, range, unit, doc); anvil
    // belongs to ndf/superstorm_anvil.
    declare_options(d, ndf::superstorm_options(), {"radius", "core", "coverage", "blend", "storm_type", "bottom_type", "min_height",
                                                    "max_height", "distortion", "height_core", "edge_noise", "noise_scale", "stretch", "wind_direction", "wall_noise", "base_relief"});
    d.param_enum("heights", {"radial", "sheet"}, "radial")
        .describe("radial: blend the map's heights toward the storm's (a tower); sheet: a flat-topped anvil sheet over the footprint");
    d.param_bool("own_coverage", false)
        .describe("where the storm's heights take a column, its coverage is the stencil's radial coverage (a tower wall the noise billows), "
                  "not the map's raised one");
    d.param_int("seed", 0).range(0, 4294967295.0).describe("noise seed");
}

void cook(CookContext& ctx) {
    ndf::SuperstormStencil s;
    s.center = ctx.get_float2("center");
    read_options(ctx, ndf::superstorm_options(), s, {"radius", "core", "coverage", "blend", "storm_type", "bottom_type", "min_height",
                                                     "max_height", "distortion", "height_core", "edge_noise", "noise_scale", "stretch", "wind_direction", "wall_noise", "base_relief"});
    s.sheet = ctx.get_string("heights") == "sheet";
    s.own_coverage = ctx.get_bool("own_coverage");
    s.seed = uint32_t(ctx.get_int("seed"));
    if (s.min_height > s.max_height) ctx.fail("'min_height' must not be above 'max_height'");
    auto in = ctx.input_field2d("in");
    if (!ndf::stencil_touches(s, in->bounds())) ctx.warn("the stencil lies entirely outside the map: it changes nothing");
    ctx.check_memory(in->byte_size(), "the NDF set");
    ctx.set_output("out", out2d(ndf::apply_superstorm(*in, s, &ctx.budget())));
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "ndf/superstorm", .version = 2, .declare = declare, .cook = cook});
}

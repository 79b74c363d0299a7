// ndf/superstorm_anvil: the anvil-spread map of a superstorm stencil.
#include "atlas/ndf/superstorm.h"
#include "atlas/graph/option_params.h"
#include "ndf/ndf_params.h"

namespace {
using namespace atlas;
using namespace atlas::ndf_nodes;

void declare(NodeDeclaration& d) {
    d.tiling(TileRule::whole("the anvil spreads across the whole map"));
    d.doc("Anvil-spread map of an HFW superstorm stencil (the NDF set has no anvil channel): channel anvil_bias = "
          "max(anvil_in, anvil x blend x g(r)) and anvil_lift = max(anvil_in's, anvil_lift x anvil x blend x g(r)) metres on the set's grid, g(r) = 1 - smoothstep(core x radius, radius, r) as in "
          "ndf/superstorm (give both the same center, radius, core, blend, stretch and wind_direction). The 2.5D preview spreads the storm's top with it "
          "(HZD's anvil bias: coverage^e in the top of a column, e = remap(f, 0.7, 0.8, 1, lerp(1, 0.5, bias))) and raises the column's "
          "top above max_height by anvil_lift. "
          "Chain several through `anvil_in`.");
    d.input("in", PortType::Field2D, "NDF set (its grid and bounds)");
    d.input("anvil_in", PortType::Field2D, "optional anvil map of the previous stencil (same grid)").optional = true;
    d.output("out", PortType::Field2D, "anvil map: channels anvil_bias in [0, 1], anvil_lift (m)");
    d.param_float2("center", {{30000, 30000}}).with_unit("m").describe("stencil centre");
    declare_options(d, ndf::superstorm_options(), {"radius", "core", "blend", "anvil", "anvil_lift", "stretch", "wind_direction"}); // the library's schema
}

void cook(CookContext& ctx) {
    ndf::SuperstormStencil s;
    s.center = ctx.get_float2("center");
    read_options(ctx, ndf::superstorm_options(), s, {"radius", "core", "blend", "anvil", "anvil_lift", "stretch", "wind_direction"});
    auto in = ctx.input_field2d("in");
    if (!ndf::stencil_touches(s, in->bounds())) ctx.warn("the stencil lies entirely outside the map: it changes nothing");
    Field2DPtr previous = ctx.has_input("anvil_in") ? ctx.input_field2d("anvil_in") : nullptr;
    ctx.check_memory(in->byte_size() / 8, "the anvil map");
    ctx.set_output("out", out2d(ndf::superstorm_anvil(*in, s, previous.get(), &ctx.budget())));
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "ndf/superstorm_anvil", .version = 2, .declare = declare, .cook = cook});
}

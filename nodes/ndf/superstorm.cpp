// ndf/superstorm: a mesocyclone stencil over an NDF set.
#include "atlas/ndf/superstorm.h"
#include "ndf/ndf_params.h"

namespace {
using namespace atlas;
using namespace atlas::ndf_nodes;

void declare(NodeDeclaration& d) {
    d.doc("HFW superstorm stencil: raises coverage, type, top type and bottom type toward the centre, writes superstorm_coverage and "
          "blends min/max height toward the storm's by distorted radial gradients. Unchanged beyond `radius`; blend 0 is a no-op. "
          "Chain several to composite stencils.");
    d.input("in", PortType::Field2D, "NDF set");
    d.output("out", PortType::Field2D, "NDF set with the stencil");
    d.param_float2("center", {{30000, 30000}}).with_unit("m").describe("stencil centre");
    d.param_float("radius", 8000).with_unit("m").describe("stencil radius (> 0)");
    d.param_float("core", 0.3).range(0, 0.999).describe("fraction of the radius at full strength");
    d.param_float("coverage", 1.0).range(0, 1).describe("coverage at the centre (never lowers the map's)");
    d.param_float("blend", 1.0).range(0, 1).describe("strength of the stencil");
    d.param_float("storm_type", 1.0).range(0, 1).describe("type and top type at the centre");
    d.param_float("bottom_type", 1.0).range(0, 1).describe("bottom type at the centre (1: ragged underside)");
    d.param_float("min_height", 800).with_unit("m").describe("storm base at the centre");
    d.param_float("max_height", 9000).with_unit("m").describe("storm top at the centre (>= min_height)");
    d.param_float("distortion", 0.3).range(0, 0.999).describe("radial wobble of the height gradients");
    d.param_float("noise_scale", 4).range(1e-6, 1e6).describe("noise cells across the radius");
    d.param_int("seed", 0).range(0, 4294967295.0).describe("noise seed");
}

void cook(CookContext& ctx) {
    ndf::SuperstormStencil s;
    s.center = ctx.get_float2("center");
    s.radius = ctx.get_float("radius");
    s.core = ctx.get_float("core");
    s.coverage = ctx.get_float("coverage");
    s.blend = ctx.get_float("blend");
    s.storm_type = ctx.get_float("storm_type");
    s.bottom_type = ctx.get_float("bottom_type");
    s.min_height = ctx.get_float("min_height");
    s.max_height = ctx.get_float("max_height");
    s.distortion = ctx.get_float("distortion");
    s.noise_scale = ctx.get_float("noise_scale");
    s.seed = uint32_t(ctx.get_int("seed"));
    if (!(s.radius > 0)) ctx.fail("'radius' must be > 0");
    if (s.min_height > s.max_height) ctx.fail("'min_height' must not be above 'max_height'");
    auto in = ctx.input_field2d("in");
    if (!ndf::stencil_touches(s, in->bounds())) ctx.warn("the stencil lies entirely outside the map: it changes nothing");
    ctx.check_memory(in->byte_size(), "the NDF set");
    ctx.set_output("out", out2d(ndf::apply_superstorm(*in, s, &ctx.budget())));
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "ndf/superstorm", .version = 1, .declare = declare, .cook = cook});
}

// ndf/precipitation_rule: HZD's "where rain is certain, storm clouds".
#include "atlas/ndf/ndf_set.h"
#include "ndf/ndf_params.h"

namespace {
using namespace atlas;
using namespace atlas::ndf_nodes;

void declare(NodeDeclaration& d) {
    d.tiling(TileRule::whole("a small 2D map (no per-tile rule declared yet)"));
    d.doc("Horizon Zero Dawn's rain rule on an NDF set: w = smoothstep(rain_start, rain_full, precipitation); type and top_type "
          "move to storm_type and coverage to at least min_coverage by w.");
    d.input("in", PortType::Field2D, "NDF set");
    d.output("out", PortType::Field2D, "NDF set with the rule applied");
    d.param_float("rain_start", 0.7).range(0, 1).describe("precipitation where the rule starts");
    d.param_float("rain_full", 1.0).range(0, 1).describe("precipitation where it applies fully (> rain_start)");
    d.param_float("min_coverage", 0.7).range(0, 1).describe("coverage floor where rain is certain (HZD: 70 %)");
    d.param_float("storm_type", 1.0).range(0, 1).describe("type where rain is certain (1 = cumulonimbus)");
}

void cook(CookContext& ctx) {
    if (!(ctx.get_float("rain_full") > ctx.get_float("rain_start"))) ctx.fail("'rain_full' must be greater than 'rain_start'");
    ndf::PrecipitationRule rule{ctx.get_float("rain_start"), ctx.get_float("rain_full"), ctx.get_float("min_coverage"), ctx.get_float("storm_type")};
    auto in = ctx.input_field2d("in");
    ctx.check_memory(in->byte_size(), "the NDF set");
    ctx.set_output("out", out2d(ndf::apply_precipitation_rule(*in, rule, &ctx.budget())));
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "ndf/precipitation_rule", .version = 1, .declare = declare, .cook = cook});
}

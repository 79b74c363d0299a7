// ndf/set: assemble the named NDF channels into one NDF set.
#include "atlas/ndf/ndf_set.h"
#include "ndf/ndf_params.h"

namespace {
using namespace atlas;
using namespace atlas::ndf_nodes;

void declare(NodeDeclaration& d) {
    d.tiling(TileRule::whole("assembles a small 2D map (no per-tile rule declared yet)"));
    d.doc("Assembles an NDF set: channels coverage, type, top_type, bottom_type, min_height, max_height (m), precipitation, "
          "superstorm_coverage. Each channel comes from its optional 1-channel input (all inputs share one resolution; the map "
          "takes the first connected input's grid) or else from its constant parameter; top_type and bottom_type default to the "
          "type channel.");
    const auto& names = ndf::ndf_channel_names();
    for (const auto& n : names) d.input(n, PortType::Field2D, "optional 1-channel map for '" + n + "'").optional = true;
    d.output("out", PortType::Field2D, "the NDF set (8 channels)");
    declare_map(d);
    d.param_float("coverage", 0.0).range(0, 1).describe("coverage where no input is connected");
    d.param_float("type", 0.0).range(0, 1).describe("cloud type where no input is connected (0 stratus .. 1 cumulonimbus)");
    d.param_float("min_height", 1500).with_unit("m").describe("cloud base where no input is connected");
    d.param_float("max_height", 4000).with_unit("m").describe("cloud top where no input is connected (>= min_height)");
    d.param_float("precipitation", 0.0).range(0, 1).describe("precipitation where no input is connected");
}

void cook(CookContext& ctx) {
    const auto& names = ndf::ndf_channel_names();
    Field2DPtr first;
    for (const auto& n : names)
        if (ctx.has_input(n)) {
            auto f = ctx.input_field2d(n);
            if (f->channels() != 1) ctx.fail("input '" + n + "' must have 1 channel (has " + std::to_string(f->channels()) + ")");
            if (first && f->resolution() != first->resolution()) ctx.fail("input '" + n + "' must have the resolution of the other inputs");
            if (!first) first = f;
        }
    const Vec2i res = first ? first->resolution() : map_resolution(ctx, ndf::ChannelCount);
    const Box2d box = first ? first->bounds() : map_bounds(ctx);
    if (ctx.get_float("min_height") > ctx.get_float("max_height")) ctx.fail("'min_height' must not be above 'max_height'");
    ctx.check_memory(field_bytes(uint64_t(res[0]) * uint64_t(res[1]), ndf::ChannelCount), "the NDF set");
    Field2D set = ndf::make_ndf_set(res, box, ctx.get_float("min_height"), ctx.get_float("max_height"), &ctx.budget());
    auto fill = [&](int c, float v) { std::fill(set.channel(c).begin(), set.channel(c).end(), v); };
    fill(ndf::Coverage, float(ctx.get_float("coverage")));
    fill(ndf::Type, float(ctx.get_float("type")));
    fill(ndf::Precipitation, float(ctx.get_float("precipitation")));
    for (int c = 0; c < ndf::ChannelCount; ++c)
        if (ctx.has_input(names[size_t(c)])) {
            auto src = ctx.input_field2d(names[size_t(c)])->channel(0);
            std::copy(src.begin(), src.end(), set.channel(c).begin());
        }
    for (int c : {int(ndf::TopType), int(ndf::BottomType)})
        if (!ctx.has_input(names[size_t(c)])) std::copy(set.channel(ndf::Type).begin(), set.channel(ndf::Type).end(), set.channel(c).begin());
    ctx.set_output("out", out2d(std::move(set)));
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "ndf/set", .version = 1, .declare = declare, .cook = cook});
}

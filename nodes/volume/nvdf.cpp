// volume/nvdf: the NVDF set from an SDF - modeling channels, field data, and the VDB grid set.
#include "atlas/volume/nvdf.h"
#include "atlas/graph/node.h"

#include <charconv>

namespace {
using namespace atlas;

std::shared_ptr<Field3D> constant_like(const Field3D& like, float v, const char* name) {
    auto f = std::make_shared<Field3D>(like.resolution(), 1, like.bounds(), std::vector<std::string>{name});
    std::fill(f->channel(0).begin(), f->channel(0).end(), v);
    return f;
}

std::string channel_list(const Field3D& f) {
    std::string s;
    for (int c = 0; c < f.channels(); ++c) s += (c ? ", " : "") + std::to_string(c) + " '" + f.channel_name(c) + "'";
    return s;
}

// The channel of input `port` that parameter `param` selects: a channel name or
// an index. Empty: a single-channel input's only channel, else the channel named
// like the port; anything else is an error (never a silent channel 0).
int select_channel(const CookContext& ctx, const Field3D& f, const std::string& port, const std::string& param) {
    const std::string& sel = ctx.get_string(param);
    if (sel.empty()) {
        if (f.channels() == 1) return 0;
        const int named = f.find_channel(port);
        if (named >= 0) return named;
        ctx.fail("input '" + port + "' has " + std::to_string(f.channels()) + " channels (" + channel_list(f) +
                 "); choose one with parameter '" + param + "' (a channel name or index)");
    }
    const int named = f.find_channel(sel);
    if (named >= 0) return named;
    int idx = -1;
    const auto [end, ec] = std::from_chars(sel.data(), sel.data() + sel.size(), idx);
    if (ec == std::errc() && end == sel.data() + sel.size() && idx >= 0 && idx < f.channels()) return idx;
    ctx.fail("parameter '" + param + "': input '" + port + "' has no channel '" + sel + "' (expected a name or an index 0.." +
             std::to_string(f.channels() - 1) + " of: " + channel_list(f) + ")");
}

void declare(NodeDeclaration& d) {
    d.doc("Builds the Nubis NVDF set from a cloud's SDF: the modeling NVDF (dimensional_profile = saturate(-sdf/depth)^exponent, "
          "detail_type, density_scale; inputs or constants), the field data (SDF encoded over [range_min, range_max]) and "
          "the four-grid set for VDB (dimensional_profile, detail_type, density_scale, sdf in metres). A multi-channel input "
          "(an imported pack's RGBA slices, say) needs its channel chosen with the *_channel parameters.");
    d.input("sdf", PortType::Field3D, "signed distance, metres, negative inside");
    d.input("detail_type", PortType::Field3D, "optional detail type (0 wispy .. 1 billowy), same grid as sdf").optional = true;
    d.input("density_scale", PortType::Field3D, "optional density scale 0..1, same grid as sdf").optional = true;
    d.tiling(TileRule::pointwise());
    d.output("modeling", PortType::Field3D, "3 channels: dimensional_profile, detail_type, density_scale (tga-slices with alpha 0 = the pack layout)");
    d.output("field_data", PortType::Field3D, "channel 'field_data': the encoded SDF, 0..1");
    d.output("vdb_set", PortType::Field3D, "4 channels: dimensional_profile, detail_type, density_scale, sdf (metres)");
    d.param_float("depth", 64).range(1e-6, 1e9).with_unit("m").describe("dimensional profile: depth where it reaches 1");
    d.param_float("exponent", 1).range(1e-3, 1e3).describe("dimensional profile: ramp exponent");
    d.param_float("detail_type", 0.5).range(0, 1).describe("detail type when the input is not connected");
    d.param_float("density_scale", 1).range(0, 1).describe("density scale when the input is not connected");
    d.param_float("range_min", -256).with_unit("m").describe("field data: distance mapped to 0");
    d.param_float("range_max", 4096).with_unit("m").describe("field data: distance mapped to 1");
    const char* sel = "(name or index); empty: the only channel, or the one named like the input (else an error)";
    d.param_string("sdf_channel", "").describe(std::string("channel of the sdf input ") + sel);
    d.param_string("detail_type_channel", "").describe(std::string("channel of the detail_type input, e.g. 'g' of a pack's modeling slices ") + sel);
    d.param_string("density_scale_channel", "").describe(std::string("channel of the density_scale input, e.g. 'b' of a pack's modeling slices ") + sel);
}

void cook(CookContext& ctx) {
    auto sdf = ctx.input_field3d("sdf");
    const int sc = select_channel(ctx, *sdf, "sdf", "sdf_channel");
    volume::DimensionalProfileOptions o;
    o.depth = ctx.get_float("depth");
    o.exponent = ctx.get_float("exponent");
    o.channel = sc;
    auto dp = std::make_shared<const Field3D>(volume::dimensional_profile(*sdf, o, &ctx.budget()));
    int dt_channel = 0, ds_channel = 0;
    Field3DPtr dt, ds;
    if (ctx.has_input("detail_type")) {
        dt = ctx.input_field3d("detail_type");
        dt_channel = select_channel(ctx, *dt, "detail_type", "detail_type_channel");
    } else {
        if (!ctx.get_string("detail_type_channel").empty()) ctx.fail("parameter 'detail_type_channel' is set but input 'detail_type' is not connected");
        dt = constant_like(*sdf, float(ctx.get_float("detail_type")), "detail_type");
    }
    if (ctx.has_input("density_scale")) {
        ds = ctx.input_field3d("density_scale");
        ds_channel = select_channel(ctx, *ds, "density_scale", "density_scale_channel");
    } else {
        if (!ctx.get_string("density_scale_channel").empty())
            ctx.fail("parameter 'density_scale_channel' is set but input 'density_scale' is not connected");
        ds = constant_like(*sdf, float(ctx.get_float("density_scale")), "density_scale");
    }
    for (const Field3D* f : {dt.get(), ds.get()})
        if (f->resolution() != sdf->resolution() || !(f->bounds() == sdf->bounds()))
            ctx.fail("detail_type and density_scale must have the sdf's resolution and bounds");
    // The modeling NVDF and the VDB set share their inputs' channels instead of
    // copying them (the cloudscape's NVDF took 536 MB, now 134; issue 49).
    auto modeling = std::make_shared<const Field3D>(
        Field3D::sharing({{dp, 0}, {dt, dt_channel}, {ds, ds_channel}}, {"dimensional_profile", "detail_type", "density_scale"}));
    auto set = std::make_shared<const Field3D>(Field3D::sharing({{modeling, 0}, {modeling, 1}, {modeling, 2}, {sdf, sc}},
                                                                {"dimensional_profile", "detail_type", "density_scale", "sdf"}));
    ctx.set_output("modeling", modeling);
    ctx.set_output("field_data", Field3DPtr(std::make_shared<Field3D>(
                                     volume::encode_field_data(*sdf, ctx.get_float("range_min"), ctx.get_float("range_max"), sc, &ctx.budget()))));
    ctx.set_output("vdb_set", set);
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "volume/nvdf", .version = 2, .declare = declare, .cook = cook});
}

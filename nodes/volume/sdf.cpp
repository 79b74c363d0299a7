// volume/sdf: signed distance field of a density at an iso level, over the whole grid.
#include "atlas/volume/sdf.h"
#include "atlas/graph/node.h"

namespace {
using namespace atlas;

void declare(NodeDeclaration& d) {
    d.doc("Signed distance (metres, negative inside where density > iso) over the whole grid. 'edt': exact Euclidean "
          "distance transform to the sub-voxel iso crossings (Felzenszwalb-Huttenlocher, within 0.5 voxel of the "
          "interpolated surface); 'fast_sweeping': OpenVDB fogToSdf (cubic voxels, first order, treats beyond the grid as empty; every distance the grid "
          "holds, at any voxel size). A dimensional profile's surface is where it leaves 0 (default iso 2/255). Reports 'seconds', "
          "'crossings' and 'iso'.");
    d.input("in", PortType::Field3D, "density");
    d.tiling(TileRule::none("an exact distance transform reads the whole grid, not a local halo; a distributed exact EDT is not written yet (docs/scale.md)"));
    d.output("out", PortType::Field3D, "signed distance, metres, channel 'sdf'");
    d.param_enum("method", {"edt", "fast_sweeping"}, "edt").describe("distance method");
    d.param_enum("input", {"auto", "density", "dimensional_profile"}, "auto")
        .describe("what the input channel holds; auto: dimensional_profile when the channel is named so, else density");
    d.param_float("iso", -1).describe("level of the surface (inside: value > iso); negative: by input, 0.5 for a density, 2/255 for a "
                                      "dimensional profile (the level that reproduces the Nubis pack's field data)");
    d.param_int("channel", 0).range(0, 255).describe("density channel");
    d.param_float("far_distance", 0).at_least(0).with_unit("m").describe("distance where the grid has no surface (0: the grid diagonal)");
    d.param_bool("border_is_outside", false).describe("treat beyond the grid as empty (edt; fast_sweeping always does)");
    d.param_int("sweeps", 1).range(1, 16).describe("fogToSdf iterations (fast_sweeping)");
    d.param_bool("check_error", false).describe("also compute the brute-force reference (small grids only) and report max/rms error in voxels");
}

void cook(CookContext& ctx) {
    volume::SdfOptions o;
    o.channel = int(ctx.get_int("channel"));
    auto in = ctx.input_field3d("in");
    if (o.channel >= in->channels())
        ctx.fail("parameter 'channel': the input has " + std::to_string(in->channels()) + " channel" + (in->channels() == 1 ? "" : "s") +
                 " (expected 0.." + std::to_string(in->channels() - 1) + "), got " + std::to_string(o.channel));
    const std::string& kind = ctx.get_string("input");
    const bool profile = kind == "dimensional_profile" || (kind == "auto" && in->channel_name(o.channel) == "dimensional_profile");
    o.iso = ctx.get_float("iso");
    if (o.iso < 0) o.iso = profile ? volume::kDimensionalProfileIso : volume::kDensityIso;
    ctx.metric("iso", o.iso);
    o.far_distance = ctx.get_float("far_distance");
    o.border_is_outside = ctx.get_bool("border_is_outside");
    volume::SdfStats st;
    Field3D out = ctx.get_string("method") == "edt"
                      ? volume::sdf_from_density_edt(*in, o, &ctx.budget(), &st, &ctx.progress_sink())
                      : volume::sdf_from_density_fast_sweeping(*in, o, int(ctx.get_int("sweeps")), &ctx.budget(), &st);
    ctx.metric("seconds", st.seconds);
    ctx.metric("crossings", double(st.crossings));
    if (ctx.get_bool("check_error")) {
        // fast_sweeping sees beyond the grid as empty: compare like with like.
        volume::SdfOptions ro = o;
        ro.border_is_outside = o.border_is_outside || ctx.get_string("method") == "fast_sweeping";
        const volume::SdfError e = volume::compare_sdf(out, volume::sdf_brute_force(*in, ro));
        ctx.metric("max_error_voxels", e.max_abs_voxels);
        ctx.metric("rms_error_voxels", e.rms_voxels);
        ctx.metric("sign_errors", double(e.sign_mismatches));
    }
    ctx.set_output("out", Field3DPtr(std::make_shared<Field3D>(std::move(out))));
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "volume/sdf", .version = 2, .declare = declare, .cook = cook});
}

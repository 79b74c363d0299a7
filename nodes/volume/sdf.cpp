// volume/sdf: signed distance field of a density at an iso level, over the whole grid.
#include "atlas/volume/sdf.h"
#include "atlas/graph/node.h"

#include <algorithm>
#include <cmath>

namespace {
using namespace atlas;

void declare(NodeDeclaration& d) {
    d.doc("Signed distance (metres, negative inside where density > iso) over the whole grid. 'edt': exact Euclidean "
          "distance transform to the sub-voxel iso crossings (Felzenszwalb-Huttenlocher, within 0.5 voxel of the "
          "interpolated surface); 'fast_sweeping': OpenVDB fogToSdf (cubic voxels, first order, treats beyond the grid as empty; every distance the grid "
          "holds, at any voxel size). A dimensional profile's surface is where it leaves 0 (default iso 2/255). Reports 'seconds', "
          "'crossings' and 'iso'.");
    d.input("in", PortType::Field3D, "density");
    // Clipped distances tile: the nearest crossing within max_distance lies within
    // ceil(max_distance / voxel) + 1 voxels in x and y (docs/scale.md).
    d.tiling(TileRule::with_grid_halo(
                 [](const NodeParams& p, const TileGrid& g) {
                     const double hx = g.bounds.size()[0] / g.res[0], hy = g.bounds.size()[1] / g.res[1];
                     const double voxels = std::ceil(p.get_float("max_distance") / std::min(hx, hy)) + 1;
                     return int(std::min(voxels, double(std::max(g.res[0], g.res[1]))));
                 },
                 [](const NodeParams& p) -> std::string {
                     if (p.get_float("max_distance") <= 0)
                         return "an exact distance transform of unclipped distances reads the whole grid, not a local halo: set "
                                "'max_distance' (metres) to clip the distances, which tiles exactly (docs/scale.md)";
                     if (p.get_string("method") != "edt")
                         return "method 'fast_sweeping' sweeps the whole grid; use method 'edt' (with 'max_distance') to tile";
                     return "";
                 })
                 .with_window());
    d.output("out", PortType::Field3D, "signed distance, metres, channel 'sdf'");
    d.param_enum("method", {"edt", "fast_sweeping"}, "edt").describe("distance method");
    d.param_enum("input", {"auto", "density", "dimensional_profile"}, "auto")
        .describe("what the input channel holds; auto: dimensional_profile when the channel is named so, else density");
    d.param_float("iso", -1).describe("level of the surface (inside: value > iso); negative: by input, 0.5 for a density, 2/255 for a "
                                      "dimensional profile (the level that reproduces the Nubis pack's field data)");
    d.param_int("channel", 0).range(0, 255).describe("density channel");
    d.param_float("far_distance", 0).at_least(0).with_unit("m").describe("distance where the grid has no surface (0: the grid diagonal)");
    d.param_float("max_distance", 0).at_least(0).with_unit("m").describe(
        "clip the distances to +-max_distance (also where the grid has no surface; far_distance is then not used); 0: unclipped. A "
        "clipped SDF can be cooked in tiles (edt), with a halo of ceil(max_distance / voxel) + 1 voxels");
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
    o.max_distance = ctx.get_float("max_distance");
    if (const TileWindow* w = ctx.window()) { // a tiled cook: `in` is a crop of the whole grid
        const Vec3d h = in->voxel_size();
        o.grid_voxel_size = {{w->grid.bounds.size()[0] / w->grid.res[0], w->grid.bounds.size()[1] / w->grid.res[1], h[2]}};
        o.grid_faces = {{w->x0 == 0, w->x1 == w->grid.res[0], w->y0 == 0, w->y1 == w->grid.res[1], true, true}};
    }
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
        Field3D ref = volume::sdf_brute_force(*in, ro);
        if (o.max_distance > 0)
            for (float& v : ref.channel(0)) v = std::clamp(v, -float(o.max_distance), float(o.max_distance));
        const volume::SdfError e = volume::compare_sdf(out, ref);
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

// volume/cumulus_paint: detail type and density scale from a cloud's SDF, as the Nubis pack has them.
#include "atlas/volume/cumulus.h"
#include "atlas/graph/node.h"

#include <algorithm>
#include <string>

namespace {
using namespace atlas;

void declare(NodeDeclaration& d) {
    d.doc("Paints a cumulus's detail type and density scale from its SDF, as Guerrilla's voxel pack has them "
          "(docs/look.md): detail type 1 (billowy) on up-facing surfaces, fading to 0 (wispy) `billow_depth` below them, "
          "0 on undersides and in the skirt above the base; density scale from `scale_floor` at the condensation height "
          "to 1 over `scale_ramp`. Defined `outside_voxels` past the cloud's surface too, so filtering at its edge reads its values; 0 beyond. Connect the "
          "outputs to volume/nvdf's detail_type and density_scale.");
    d.input("sdf", PortType::Field3D, "the cloud's signed distance (m, negative inside)");
    d.output("detail_type", PortType::Field3D, "channel 'detail_type' (0 wispy .. 1 billowy)");
    // The SDF's gradient reads one neighbour each way.
    d.tiling(TileRule::with_halo([](const NodeParams&) { return 1; }).with_window());
    d.output("density_scale", PortType::Field3D, "channel 'density_scale'");
    d.param_float("base_height", 0).range(-1e9, 1e9).with_unit("m").describe("condensation height (the flat base)");
    d.param_float("billow_depth", 200).range(1e-3, 1e9).with_unit("m").describe("depth below an up-facing surface where detail type reaches 0");
    d.param_float("facing_low", -0.9).range(-1, 1).describe("upward normal component where detail type starts (undersides below it stay wispy)");
    d.param_float("facing_high", 0.2).range(-1, 1).describe("upward normal component where detail type is full");
    d.param_float("skirt", 40).range(0, 1e9).with_unit("m").describe("height above the base kept wispy");
    d.param_float("scale_floor", 0.2).range(0, 1).describe("density scale at the base (the pack's clouds are thin at the base: low scale draws them white)");
    d.param_float("scale_ramp", 500).range(0, 1e9).with_unit("m").describe("height over which density scale rises to 1");
    d.param_float("outside_voxels", 3).range(0, 1e9).describe("voxels outside the cloud still painted; beyond, both channels are 0 "
                                                          "(nothing samples there; flat texture blocks, sparse VDB grids)");
}

void cook(CookContext& ctx) {
    auto sdf = ctx.input_field3d("sdf");
    ctx.check_memory(field_bytes(sdf->voxel_count(), 2), "the detail type and density scale grids");
    volume::CumulusPaintSpec s;
    s.base_height = ctx.get_float("base_height");
    s.billow_depth = ctx.get_float("billow_depth");
    s.facing_low = ctx.get_float("facing_low");
    s.facing_high = ctx.get_float("facing_high");
    if (!(s.facing_high > s.facing_low)) ctx.fail("'facing_high' must be above 'facing_low'");
    s.skirt = ctx.get_float("skirt");
    s.scale_floor = ctx.get_float("scale_floor");
    s.scale_ramp = ctx.get_float("scale_ramp");
    s.outside_voxels = ctx.get_float("outside_voxels");
    // A condensation height at or above the cloud's top leaves no cloud above its base. A tile holds
    // part of a cloud, so a tiled cook leaves the check to the untiled one (a tile of a cloud's skirt
    // would be refused for the tile's own top).
    double top = -1e300;
    if (!ctx.window()) {
        for (int z = 0; z < sdf->nz(); ++z)
            for (int y = 0; y < sdf->ny(); ++y)
                for (int x = 0; x < sdf->nx(); ++x)
                    if (sdf->at(0, x, y, z) < 0) top = std::max(top, sdf->voxel_center(x, y, z)[2]);
    }
    if (top > -1e300 && s.base_height >= top)
        ctx.fail("'base_height' " + std::to_string(s.base_height) + " m is at or above the cloud's top (" + std::to_string(top) +
                 " m): the condensation height must lie below the cloud");
    const GridFrame frame = ctx.frame(*sdf);
    volume::CumulusChannels c = volume::cumulus_channels(*sdf, s, &ctx.budget(), &frame);
    ctx.set_output("detail_type", Field3DPtr(std::make_shared<Field3D>(std::move(c.detail_type))));
    ctx.set_output("density_scale", Field3DPtr(std::make_shared<Field3D>(std::move(c.density_scale))));
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "volume/cumulus_paint", .version = 2, .declare = declare, .cook = cook});
}

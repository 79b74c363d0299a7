// volume/billows: cumulus lobes on lobes and towers on a coarse shape (spheres in, spheres out).
#include "atlas/volume/cumulus.h"
#include "spheres_param.h"

namespace {
using namespace atlas;

void declare(NodeDeclaration& d) {
    d.doc("Grows a coarse shape into cumulus spheres, as Houdini's Cloud Shape Replicate does: towers (stacks of tapering "
          "spheres) rise from the highest spheres, then each generation places smaller spheres on the exposed surface of "
          "the previous one, facing up and out (none on undersides, none below the base). Feed the result to "
          "volume/metaballs (kernel sphere, blend max) for crisp lobes at several scales; the Nubis pack's clouds have "
          "lobes of 25-80 m (docs/look.md).");
    d.input("points", PortType::Points, "optional shape spheres; attribute 'radius' (m)").optional = true;
    d.output("out", PortType::Points, "the shape's spheres, the towers and the billows; attribute 'radius' (m)");
    volume_nodes::declare_spheres(d);
    d.param_float("default_radius", 64).range(1e-6, 1e9).with_unit("m").describe("radius of points without a 'radius' attribute");
    d.param_int("levels", 2).range(0, 6).describe("generations of smaller spheres");
    d.param_int("children", 10).range(0, 64).describe("spheres tried on each sphere of the previous generation");
    d.param_float("ratio", 0.45).range(0.05, 0.95).describe("child radius / parent radius");
    d.param_float("jitter", 0.3).range(0, 1).describe("relative spread of the child radii");
    d.param_float("up_bias", 0.6).range(0, 1).describe("0: children all round; 1: all on the upper half (billows face up)");
    d.param_float("min_up", -0.3).range(-1, 1).describe("no child in directions whose z is below this (smooth undersides)");
    d.param_float("sink", 0.75).range(0, 1.5).describe("child centre distance from its parent's centre, in parent radii");
    d.param_float("min_radius", 8).range(1e-3, 1e9).with_unit("m").describe("smaller children are not made (about a voxel)");
    d.param_float("base_height", 0).range(-1e9, 1e9).with_unit("m").describe("condensation height: no child below it");
    d.param_int("towers", 0).range(0, 64).describe("towers rising from the highest spheres");
    d.param_float("tower_height", 200).range(0, 1e9).with_unit("m").describe("how far a tower rises above its sphere");
    d.param_float("tower_taper", 0.85).range(0.31, 1).describe("radius ratio from one tower sphere to the next");
    d.param_float("tower_lean", 0.15).range(0, 1).describe("lateral drift per tower step, in radii");
    d.param_int("seed", 1).range(0, 4294967295.0).describe("placement seed");
}

void cook(CookContext& ctx) {
    Points pts;
    if (ctx.has_input("points")) pts = *ctx.input_points("points");
    std::vector<float> radius = pts.attributes.count("radius") ? pts.attributes["radius"]
                                                               : std::vector<float>(pts.positions.size(), float(ctx.get_float("default_radius")));
    volume_nodes::append_spheres(ctx, pts, radius);
    pts.attributes = {{"radius", std::move(radius)}};
    if (pts.positions.empty()) ctx.fail("no shape: give 'spheres' or connect 'points'");
    volume::BillowSpec s;
    s.levels = int(ctx.get_int("levels"));
    s.children = int(ctx.get_int("children"));
    s.ratio = ctx.get_float("ratio");
    s.jitter = ctx.get_float("jitter");
    s.up_bias = ctx.get_float("up_bias");
    s.min_up = ctx.get_float("min_up");
    s.sink = ctx.get_float("sink");
    s.min_radius = ctx.get_float("min_radius");
    s.base_height = ctx.get_float("base_height");
    s.towers = int(ctx.get_int("towers"));
    s.tower_height = ctx.get_float("tower_height");
    s.tower_taper = ctx.get_float("tower_taper");
    s.tower_lean = ctx.get_float("tower_lean");
    s.seed = uint32_t(ctx.get_int("seed"));
    Points out = volume::billow_spheres(pts, s);
    ctx.metric("spheres_in", double(pts.positions.size()));
    ctx.metric("spheres_out", double(out.positions.size()));
    ctx.set_output("out", PointsPtr(std::make_shared<Points>(std::move(out))));
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "volume/billows", .version = 1, .declare = declare, .cook = cook});
}

// volume/sdf_spheres: the spheres that fill a shape's SDF (a solver's cloud, a mesh, any field), for volume/billows.
#include "atlas/volume/cumulus.h"
#include "atlas/graph/node.h"

namespace {
using namespace atlas;

void declare(NodeDeclaration& d) {
    d.doc("Fills a shape given as a signed distance field with spheres: the deepest unclaimed voxel first, its inscribed "
          "ball (radius = its depth, at most max_radius), until every voxel at least min_radius deep is claimed. Turns a "
          "solver's grown cloud, a mesh or any field into coarse spheres that volume/billows grows into cumulus (docs/look.md).");
    d.input("sdf", PortType::Field3D, "signed distance, metres, negative inside");
    d.output("out", PortType::Points, "sphere centres, attribute 'radius' (m)");
    d.param_float("min_radius", 16).range(1e-3, 1e9).with_unit("m").describe("parts thinner than this get no sphere of their own");
    d.param_float("max_radius", 1e9).range(1e-3, 1e9).with_unit("m").describe("larger balls are capped: a tall tower becomes a stack");
    d.param_float("cover", 0.7).range(0.05, 1).describe("a sphere claims the voxels within this fraction of its radius");
    d.param_int("max_spheres", 4096).range(1, 1000000).describe("at most this many spheres");
}

void cook(CookContext& ctx) {
    volume::SphereFillSpec s;
    s.min_radius = ctx.get_float("min_radius");
    s.max_radius = ctx.get_float("max_radius");
    if (s.max_radius < s.min_radius) ctx.fail("'max_radius' must be at least 'min_radius'");
    s.cover = ctx.get_float("cover");
    s.max_spheres = int(ctx.get_int("max_spheres"));
    Points out = volume::spheres_from_sdf(*ctx.input_field3d("sdf"), s);
    ctx.metric("spheres", double(out.positions.size()));
    ctx.set_output("out", PointsPtr(std::make_shared<Points>(std::move(out))));
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "volume/sdf_spheres", .version = 1, .declare = declare, .cook = cook});
}

// volume/interior_fill: samples inside a closed mesh, sized by local thickness (TetGen).
#include "atlas/volume/interior_fill.h"
#include "atlas/graph/node.h"

namespace {
using namespace atlas;

void declare(NodeDeclaration& d) {
    d.doc("Tetrahedralises a closed mesh with TetGen, draws 8 x target_samples uniform candidates in its volume and keeps exactly "
          "target_samples of them by farthest-point selection (evenly spread: separate puffs); "
          "each sample's 'radius' is its distance to the surface ('thickness') times radius_scale. Feed to volume/metaballs "
          "to grow a billowy cloud that fills the shape.");
    d.input("mesh", PortType::Mesh, "closed, non-self-intersecting mesh");
    d.output("out", PortType::Points, "samples with attributes 'radius' and 'thickness' (metres)");
    d.param_int("target_samples", 2000).range(1, 10000000).describe("number of samples returned (exactly; evenly spread up to 20,000)");
    d.param_float("radius_scale", 0.9).range(1e-6, 100).describe("radius = thickness x radius_scale");
    d.param_float("min_radius", 0).range(0, 1e9).with_unit("m").describe("lower clamp on radii");
    d.param_int("seed", 1).range(0, 4294967295.0).describe("sampling seed");
}

void cook(CookContext& ctx) {
    volume::InteriorFillOptions o;
    o.target_samples = int(ctx.get_int("target_samples"));
    o.radius_scale = ctx.get_float("radius_scale");
    o.min_radius = ctx.get_float("min_radius");
    o.seed = uint32_t(ctx.get_int("seed"));
    volume::InteriorFillStats st;
    auto pts = std::make_shared<Points>(volume::fill_mesh_interior(*ctx.input_mesh("mesh"), o, &st));
    ctx.metric("tetrahedra", double(st.tetrahedra));
    ctx.metric("samples", double(st.samples));
    ctx.metric("interior_volume_m3", st.interior_volume);
    ctx.metric("max_thickness_m", st.max_thickness);
    ctx.set_output("out", PointsPtr(pts));
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "volume/interior_fill", .version = 2, .declare = declare, .cook = cook});
}

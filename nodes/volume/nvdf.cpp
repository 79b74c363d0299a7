// volume/nvdf: the NVDF set from an SDF - modeling channels, field data, and the VDB grid set.
#include "atlas/volume/nvdf.h"
#include "atlas/graph/node.h"

namespace {
using namespace atlas;

std::shared_ptr<Field3D> constant_like(const Field3D& like, float v, const char* name) {
    auto f = std::make_shared<Field3D>(like.resolution(), 1, like.bounds(), std::vector<std::string>{name});
    std::fill(f->channel(0).begin(), f->channel(0).end(), v);
    return f;
}

void declare(NodeDeclaration& d) {
    d.doc("Builds the Nubis NVDF set from a cloud's SDF: the modeling NVDF (dimensional_profile = saturate(-sdf/depth)^exponent, "
          "detail_type, density_scale; inputs or constants), the field data (SDF encoded over [range_min, range_max]) and "
          "the four-grid set for VDB (dimensional_profile, detail_type, density_scale, sdf in metres).");
    d.input("sdf", PortType::Field3D, "signed distance, metres, negative inside");
    d.input("detail_type", PortType::Field3D, "optional detail type (0 wispy .. 1 billowy), same grid as sdf").optional = true;
    d.input("density_scale", PortType::Field3D, "optional density scale 0..1, same grid as sdf").optional = true;
    d.output("modeling", PortType::Field3D, "3 channels: dimensional_profile, detail_type, density_scale (tga-slices with alpha 0 = the pack layout)");
    d.output("field_data", PortType::Field3D, "channel 'field_data': the encoded SDF, 0..1");
    d.output("vdb_set", PortType::Field3D, "4 channels: dimensional_profile, detail_type, density_scale, sdf (metres)");
    d.param_float("depth", 64).range(1e-6, 1e9).with_unit("m").describe("dimensional profile: depth where it reaches 1");
    d.param_float("exponent", 1).range(1e-3, 1e3).describe("dimensional profile: ramp exponent");
    d.param_float("detail_type", 0.5).range(0, 1).describe("detail type when the input is not connected");
    d.param_float("density_scale", 1).range(0, 1).describe("density scale when the input is not connected");
    d.param_float("range_min", -256).with_unit("m").describe("field data: distance mapped to 0");
    d.param_float("range_max", 4096).with_unit("m").describe("field data: distance mapped to 1");
}

void cook(CookContext& ctx) {
    auto sdf = ctx.input_field3d("sdf");
    volume::DimensionalProfileOptions o;
    o.depth = ctx.get_float("depth");
    o.exponent = ctx.get_float("exponent");
    const Field3D dp = volume::dimensional_profile(*sdf, o, &ctx.budget());
    Field3DPtr dt = ctx.has_input("detail_type") ? ctx.input_field3d("detail_type") : constant_like(*sdf, float(ctx.get_float("detail_type")), "detail_type");
    Field3DPtr ds = ctx.has_input("density_scale") ? ctx.input_field3d("density_scale")
                                                   : constant_like(*sdf, float(ctx.get_float("density_scale")), "density_scale");
    auto modeling = std::make_shared<Field3D>(volume::assemble_modeling_nvdf(dp, *dt, *ds, &ctx.budget()));
    auto set = std::make_shared<Field3D>(sdf->resolution(), 4, sdf->bounds(),
                                         std::vector<std::string>{"dimensional_profile", "detail_type", "density_scale", "sdf"}, &ctx.budget());
    for (int c = 0; c < 3; ++c) std::copy(modeling->channel(c).begin(), modeling->channel(c).end(), set->channel(c).begin());
    std::copy(sdf->channel(0).begin(), sdf->channel(0).end(), set->channel(3).begin());
    ctx.set_output("modeling", Field3DPtr(modeling));
    ctx.set_output("field_data", Field3DPtr(std::make_shared<Field3D>(
                                     volume::encode_field_data(*sdf, ctx.get_float("range_min"), ctx.get_float("range_max"), 0, &ctx.budget()))));
    ctx.set_output("vdb_set", Field3DPtr(set));
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "volume/nvdf", .version = 1, .declare = declare, .cook = cook});
}

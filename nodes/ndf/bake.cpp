// ndf/bake: an NDF set baked into a 3D dimensional profile.
#include "atlas/ndf/bake.h"
#include "ndf/ndf_params.h"

namespace {
using namespace atlas;
using namespace atlas::ndf_nodes;

void declare(NodeDeclaration& d) {
    d.tiling(TileRule::whole("bakes a small 2D map into profile columns (no per-tile rule declared yet)"));
    d.doc("Bakes an NDF set into the voxel world's dimensional profile (Nubis3 2.5D authoring data). vertical_profile: coverage * "
          "bottom(bottom_type, f) * top(top_type, f); envelope: coverage * f^2 * (1 - f)^1.5; f = (z - min_height) / (max_height - "
          "min_height), 0 outside [0, 1]. The set is sampled bilinearly (clamped) at voxel centres.");
    d.input("in", PortType::Field2D, "NDF set");
    d.output("out", PortType::Field3D, "dimensional profile (1 channel)");
    d.param_enum("formula", {"vertical_profile", "envelope"}, "vertical_profile").describe("profile formula");
    d.param_int3("resolution", {{256, 256, 64}}).range(1, 65536).with_unit("voxels").describe("voxels along x, y, z").follows_proxy(ProxyScale::Cells);
    d.param_float("z_min", 0).with_unit("m").describe("volume bottom (x, y take the set's bounds)");
    d.param_float("z_max", 10000).with_unit("m").describe("volume top");
}

void cook(CookContext& ctx) {
    auto in = ctx.input_field2d("in");
    const Vec3i res = ctx.get_int3("resolution");
    const Box3d box{{{in->bounds().min[0], in->bounds().min[1], ctx.get_float("z_min")}},
                    {{in->bounds().max[0], in->bounds().max[1], ctx.get_float("z_max")}}};
    if (!box.valid()) ctx.fail("'z_max' must be greater than 'z_min'");
    ctx.check_memory(field_bytes(uint64_t(res[0]) * uint64_t(res[1]) * uint64_t(res[2]), 1), "the baked volume");
    const auto formula = ctx.get_string("formula") == "envelope" ? ndf::BakeFormula::Envelope : ndf::BakeFormula::VerticalProfile;
    ctx.set_output("out", Field3DPtr(std::make_shared<const Field3D>(ndf::bake_ndf_set(*in, formula, ndf::VerticalProfile{}, res, box, &ctx.budget()))));
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "ndf/bake", .version = 1, .declare = declare, .cook = cook});
}

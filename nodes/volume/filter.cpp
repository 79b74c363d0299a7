// volume/filter: smooth (Gaussian), dilate (max) or erode (min) a field.
#include "atlas/volume/edit.h"
#include "atlas/graph/node.h"

#include <cmath>

namespace {
using namespace atlas;

void declare(NodeDeclaration& d) {
    d.doc("smooth: separable Gaussian blur (sigma in voxels, edges clamped); dilate / erode: grayscale max / min over a "
          "cube of (2 radius + 1)^3 voxels. All channels.");
    d.input("in", PortType::Field3D, "field");
    d.output("out", PortType::Field3D, "filtered field");
    // Separable passes reach ceil(3 sigma) (smooth) or radius (dilate, erode) voxels each way; edges clamp
    // at the grid's own faces only, which a crop grown by that halo shares.
    d.tiling(TileRule::with_halo([](const NodeParams& p) {
        return p.get_string("op") == "smooth" ? int(std::ceil(3 * p.get_float("sigma"))) : int(p.get_int("radius"));
    }));
    d.param_enum("op", {"smooth", "dilate", "erode"}, "smooth").describe("filter");
    d.param_float("sigma", 1).range(0, 1000).with_unit("voxels").describe("Gaussian sigma (smooth)").follows_proxy(ProxyScale::CellLength);
    d.param_int("radius", 1).range(0, 1000).with_unit("voxels").describe("cube half size (dilate, erode)").follows_proxy(ProxyScale::CellLength);
}

void cook(CookContext& ctx) {
    auto in = ctx.input_field3d("in");
    const std::string& op = ctx.get_string("op");
    Field3D out = op == "smooth"   ? volume::smooth(*in, ctx.get_float("sigma"), &ctx.budget())
                  : op == "dilate" ? volume::dilate(*in, int(ctx.get_int("radius")), &ctx.budget())
                                   : volume::erode(*in, int(ctx.get_int("radius")), &ctx.budget());
    ctx.set_output("out", Field3DPtr(std::make_shared<Field3D>(std::move(out))));
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "volume/filter", .version = 1, .declare = declare, .cook = cook});
}

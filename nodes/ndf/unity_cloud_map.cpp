// ndf/unity_cloud_map: Unity HDRP volumetric clouds (manual mode) cloud map layout.
#include "atlas/ndf/exporters.h"
#include "ndf/ndf_params.h"

namespace {
using namespace atlas;
using namespace atlas::ndf_nodes;

void declare(NodeDeclaration& d) {
    d.tiling(TileRule::whole("a small 2D map (no per-tile rule declared yet)"));
    d.doc("Unity HDRP volumetric clouds, manual mode cloud map: R coverage, G rain (precipitation), B cloud type, A maximum cloud "
          "height normalised in the layer, (max_height - layer_bottom) / (layer_top - layer_bottom) clamped to [0, 1]. Write it "
          "linear, uncompressed (PNG 8-bit or EXR); in Unity import it with sRGB off and compression none.");
    d.input("in", PortType::Field2D, "NDF set");
    d.output("out", PortType::Field2D, "RGBA cloud map");
    d.param_float("layer_bottom", 0).with_unit("m").describe("cloud layer bottom altitude (Unity: Lower Cloud Altitude)");
    d.param_float("layer_top", 10000).with_unit("m").describe("cloud layer top altitude, > layer_bottom (Unity: lower altitude + Cloud Thickness)");
}

void cook(CookContext& ctx) {
    auto in = ctx.input_field2d("in");
    try {
        ctx.set_output("out", out2d(ndf::unity_cloud_map(*in, {ctx.get_float("layer_bottom"), ctx.get_float("layer_top")}, &ctx.budget())));
    } catch (const Error& e) {
        ctx.fail(e.what());
    }
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "ndf/unity_cloud_map", .version = 1, .declare = declare, .cook = cook});
}

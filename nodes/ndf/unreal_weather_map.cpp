// ndf/unreal_weather_map: Atlas's weather-map layout for Unreal Engine's volumetric cloud material.
#include "atlas/ndf/exporters.h"
#include "ndf/ndf_params.h"

namespace {
using namespace atlas;
using namespace atlas::ndf_nodes;

void declare(NodeDeclaration& d) {
    d.tiling(TileRule::whole("a small 2D map (no per-tile rule declared yet)"));
    d.doc("Unreal Engine volumetric cloud weather map (Atlas layout; Unreal publishes none): R coverage, G cloud type (the profile "
          "LUT's x), B min_height and A max_height normalised in the layer, (h - layer_bottom) / (layer_top - layer_bottom) "
          "clamped to [0, 1]. Linear; import with sRGB off. docs/ndf.md gives the material's HLSL (Custom node).");
    d.input("in", PortType::Field2D, "NDF set");
    d.output("out", PortType::Field2D, "RGBA weather map");
    d.param_float("layer_bottom", 0).with_unit("m").describe("Layer Bottom Altitude of the Volumetric Cloud component");
    d.param_float("layer_top", 10000).with_unit("m").describe("layer bottom + Layer Height, > layer_bottom");
}

void cook(CookContext& ctx) {
    auto in = ctx.input_field2d("in");
    try {
        ctx.set_output("out", out2d(ndf::unreal_weather_map(*in, {ctx.get_float("layer_bottom"), ctx.get_float("layer_top")}, &ctx.budget())));
    } catch (const Error& e) {
        ctx.fail(e.what());
    }
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "ndf/unreal_weather_map", .version = 1, .declare = declare, .cook = cook});
}

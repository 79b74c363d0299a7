// ndf/unity_cloud_layer: Unity HDRP cloud layer (2D) lat-long opacity map from an NDF set.
#include "atlas/ndf/exporters.h"
#include "ndf/ndf_params.h"

#include <cmath>

namespace {
using namespace atlas;
using namespace atlas::ndf_nodes;

void declare(NodeDeclaration& d) {
    d.tiling(TileRule::whole("a lat-long texture of its own"));
    d.doc("Unity HDRP cloud layer map: an RGBA lat-long texture of opacities R cumulus = coverage x w, G stratus = coverage x (1 - w) "
          "(w = clamp(1.5 type, 0, 1)), B cirrus and A wispy from the optional maps (sampled at world XY by their own bounds, e.g. "
          "ndf/cirrus with the weather map's bounds). The set's XY map lies on a flat plane "
          "`altitude` m above the eye; column x looks along azimuth 360 (x + 0.5) / W degrees from world +X toward +Y, row y at "
          "elevation -90 + 180 (y + 0.5) / H (or 90 (y + 0.5) / H with upper_hemisphere_only); below the horizon all 0. Output "
          "bounds are degrees (azimuth, elevation).");
    d.input("in", PortType::Field2D, "NDF set");
    d.input("cirrus", PortType::Field2D, "optional cirrus opacity map over the world XY (any resolution)").optional = true;
    d.input("wispy", PortType::Field2D, "optional wispy opacity map over the world XY (any resolution)").optional = true;
    d.output("out", PortType::Field2D, "RGBA lat-long cloud map");
    d.param_int2("resolution", {{1024, 512}}).range(1, 16384).with_unit("texels").describe("lat-long texels (azimuth x elevation)");
    d.param_bool("upper_hemisphere_only", false).describe("true: the rows cover the sky above the horizon only (Unity's Upper Hemisphere Only)");
    d.param_float("altitude", 3000).with_unit("m").describe("height of the cloud plane above the eye (> 0)");
    d.param_float2("eye", {{30000, 30000}}).with_unit("m").describe("world XY of the viewer (default: the centre of a 60 km map)");
    d.param_bool("tileable", false).describe("true: the maps repeat beyond their bounds; false: nothing beyond them");
    d.param_string("cirrus_channel", "0").describe("channel of the cirrus map to use, by name or index");
    d.param_string("wispy_channel", "0").describe("channel of the wispy map to use, by name or index");
}

void cook(CookContext& ctx) {
    auto in = ctx.input_field2d("in");
    Field2DPtr cirrus = ctx.has_input("cirrus") ? ctx.input_field2d("cirrus") : nullptr;
    Field2DPtr wispy = ctx.has_input("wispy") ? ctx.input_field2d("wispy") : nullptr;
    ndf::UnityCloudLayerOptions o;
    o.resolution = ctx.get_int2("resolution");
    ctx.check_memory(field_bytes(uint64_t(o.resolution[0]) * uint64_t(o.resolution[1]), 4), "the cloud layer map");
    o.upper_hemisphere_only = ctx.get_bool("upper_hemisphere_only");
    o.altitude = ctx.get_float("altitude");
    o.eye = ctx.get_float2("eye");
    o.tileable = ctx.get_bool("tileable");
    try {
        const int cc = cirrus ? channel_param(ctx, *cirrus, "cirrus_channel") : 0;
        const int wc = wispy ? channel_param(ctx, *wispy, "wispy_channel") : 0;
        ctx.set_output("out", out2d(ndf::unity_cloud_layer(*in, cirrus.get(), cc, wispy.get(), wc, o, &ctx.budget())));
    } catch (const Error& e) {
        ctx.fail(e.what());
    }
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "ndf/unity_cloud_layer", .version = 2, .declare = declare, .cook = cook});
}

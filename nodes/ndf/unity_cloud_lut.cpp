// ndf/unity_cloud_lut: Unity HDRP volumetric clouds (manual mode) cloud LUT.
#include "atlas/ndf/exporters.h"
#include "ndf/ndf_params.h"

namespace {
using namespace atlas;
using namespace atlas::ndf_nodes;

void declare(NodeDeclaration& d) {
    d.tiling(TileRule::whole("a LUT of its own"));
    d.doc("Unity HDRP volumetric clouds, manual mode cloud LUT, sampled by HDRP at UV (cloud type, normalised height in the "
          "layer), cell-centred: R density = the vertical profile's HZD type blend, G erosion = 1 - erosion_core x density (full "
          "erosion at the thin edges, less in the dense core), B ambient = 1 - ao_strength x (fraction of the column's cloud mass "
          "above), HDRP's ambient multiplier. Reports metric max_error: the largest |bilinear LUT - analytic| over all channels. "
          "Write it linear and uncompressed (EXR, or 16-bit PNG).");
    d.output("out", PortType::Field2D, "the LUT (channels density, erosion, ambient)");
    d.param_int2("resolution", {{64, 128}}).range(2, 8192).with_unit("texels").describe("types x heights");
    d.param_string("gradients", "0 0.05 0.1 0.25; 0 0.1 0.3 0.55; 0 0.1 0.55 0.85; 0 0.05 0.8 1")
        .describe("per type 'bottom_start bottom_end top_start top_end' (height fractions), for stratus; stratocumulus; cumulus; cumulonimbus");
    d.param_float("erosion_core", 0.5).range(0, 1).describe("erosion removed in the densest core (G = 1 - erosion_core x density)");
    d.param_float("ao_strength", 0.6).range(0, 1).describe("ambient occlusion under the whole column (B = 1 - ao_strength x mass above)");
}

void cook(CookContext& ctx) {
    const Vec2i r = ctx.get_int2("resolution");
    ctx.check_memory(field_bytes(uint64_t(r[0]) * uint64_t(r[1]), 3), "the LUT");
    try {
        const ndf::VerticalProfile p = ndf::parse_profile_gradients(ctx.get_string("gradients"));
        ndf::UnityCloudLutOptions o;
        o.types = r[0];
        o.heights = r[1];
        o.erosion_core = ctx.get_float("erosion_core");
        o.ao_strength = ctx.get_float("ao_strength");
        Field2D lut = ndf::unity_cloud_lut(p, o, &ctx.budget());
        ctx.metric("max_error", ndf::unity_cloud_lut_max_error(lut, p, o, 2));
        ctx.set_output("out", out2d(std::move(lut)));
    } catch (const Error& e) {
        ctx.fail(e.what());
    }
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "ndf/unity_cloud_lut", .version = 1, .declare = declare, .cook = cook});
}

// ndf/unity_cloud_map: Unity HDRP volumetric clouds (manual mode) cloud map layout.
#include "atlas/ndf/ndf_set.h"
#include "ndf/ndf_params.h"

namespace {
using namespace atlas;
using namespace atlas::ndf_nodes;

void declare(NodeDeclaration& d) {
    d.doc("Unity HDRP volumetric clouds, manual mode cloud map: R coverage, G rain (precipitation), B cloud type, A maximum cloud "
          "height normalised in the layer, (max_height - layer_bottom) / (layer_top - layer_bottom) clamped to [0, 1]. Write it "
          "linear, uncompressed (PNG 8-bit or EXR).");
    d.input("in", PortType::Field2D, "NDF set");
    d.output("out", PortType::Field2D, "RGBA cloud map");
    d.param_float("layer_bottom", 0).with_unit("m").describe("cloud layer bottom altitude");
    d.param_float("layer_top", 10000).with_unit("m").describe("cloud layer top altitude (> layer_bottom)");
}

void cook(CookContext& ctx) {
    auto in = ctx.input_field2d("in");
    ndf::check_ndf_set(*in);
    const double lo = ctx.get_float("layer_bottom"), hi = ctx.get_float("layer_top");
    if (!(hi > lo)) ctx.fail("'layer_top' must be greater than 'layer_bottom'");
    auto out = ctx.make_field2d(in->resolution(), 4, in->bounds(), {"r", "g", "b", "a"});
    const int src[3] = {ndf::Coverage, ndf::Precipitation, ndf::Type};
    for (int c = 0; c < 3; ++c) {
        auto s = in->channel(src[c]);
        std::copy(s.begin(), s.end(), out->channel(c).begin());
    }
    auto mh = in->channel(ndf::MaxHeight);
    auto a = out->channel(3);
    for (size_t i = 0; i < mh.size(); ++i) {
        const double v = (mh[i] - lo) / (hi - lo);
        a[i] = float(std::isnan(v) ? 0.0 : std::clamp(v, 0.0, 1.0));
    }
    ctx.set_output("out", Field2DPtr(out));
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "ndf/unity_cloud_map", .version = 1, .declare = declare, .cook = cook});
}

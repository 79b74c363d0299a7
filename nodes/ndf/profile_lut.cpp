// ndf/profile_lut: the vertical-profile LUT (cloud type x height fraction).
#include "atlas/ndf/vertical_profile.h"
#include "ndf/ndf_params.h"

#include <sstream>

namespace {
using namespace atlas;
using namespace atlas::ndf_nodes;

void declare(NodeDeclaration& d) {
    d.tiling(TileRule::whole("a LUT of its own"));
    d.doc("Vertical-profile LUT: x = cloud type (0 stratus, 1/3 stratocumulus, 2/3 cumulus, 1 cumulonimbus), y = height fraction; "
          "channels bottom (rise), top (fall), density (HZD blend). End-aligned texels: sample at texel (0.5 + type (W-1), "
          "0.5 + f (H-1)). Reports metric max_error: the largest |LUT - analytic| under that bilinear lookup.");
    d.output("out", PortType::Field2D, "the LUT (3 channels)");
    d.param_int2("resolution", {{64, 128}}).range(2, 8192).with_unit("texels").describe("types x heights");
    d.param_string("gradients", "0 0.05 0.1 0.25; 0 0.1 0.3 0.55; 0 0.1 0.55 0.85; 0 0.05 0.8 1")
        .describe("per type 'bottom_start bottom_end top_start top_end' (height fractions), for stratus; stratocumulus; cumulus; cumulonimbus");
}

void cook(CookContext& ctx) {
    ndf::VerticalProfile p;
    std::stringstream all(ctx.get_string("gradients"));
    std::string entry;
    size_t i = 0;
    while (std::getline(all, entry, ';')) {
        std::istringstream in(entry);
        ndf::TypeGradient g{};
        std::string rest;
        if (!(in >> g.b0 >> g.b1 >> g.t0 >> g.t1) || (in >> rest)) ctx.fail("'gradients' entry " + std::to_string(i + 1) + " must be 4 numbers");
        if (i >= 4) ctx.fail("'gradients' has more than 4 entries");
        p.types[i++] = g;
    }
    if (i != 4) ctx.fail("'gradients' needs 4 entries (stratus; stratocumulus; cumulus; cumulonimbus)");
    try {
        p.validate();
    } catch (const Error& e) {
        ctx.fail(e.what());
    }
    const Vec2i r = ctx.get_int2("resolution");
    Field2D lut = ndf::build_profile_lut(p, r[0], r[1], &ctx.budget());
    ctx.metric("max_error", ndf::profile_lut_max_error(lut, p, 4));
    ctx.set_output("out", out2d(std::move(lut)));
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "ndf/profile_lut", .version = 1, .declare = declare, .cook = cook});
}

// sim/sounding: the ambient atmosphere the cloud grows in (lapse rates, capping
// inversion, humidity profile), as a record for sim/cloud_growth plus its
// hydrostatic profile for inspection.
#include "atlas/graph/option_params.h"
#include "atlas/sim/simulation.h"
#include "atlas/sim/sounding_options.h"
#include "sim_params.h"

#include <cmath>

namespace {
using namespace atlas;

void declare(NodeDeclaration& d) {
    d.tiling(TileRule::whole("a parameter record and a vertical profile, not maps of the world"));
    d.doc("Ambient sounding for sim/cloud_growth: potential temperature with a lapse rate, a capping inversion (height, "
          "jump, depth) and a relative-humidity profile; or, with total_water > 0, a saturated moist-neutral atmosphere. "
          "'out' is the parameter record (1 x 1, one channel per member, see docs/solver.md); 'profile' is the hydrostatic "
          "reference at 'levels' heights dz apart (channels theta K, temperature K, pressure Pa, rho kg/m^3, qv kg/kg, rh).");
    d.output("out", PortType::Field2D, "sounding record for sim/cloud_growth's 'sounding' input");
    d.output("profile", PortType::Field2D, "1 x levels: theta, temperature, pressure, rho, qv, rh at cell-centre heights");
    // The library's schema (ranges, units, docs) with the node's own defaults.
    declare_options(d, sim::sounding_options(), sim::capped_boundary_layer_sounding());
    d.param_int("levels", 64).range(1, 4096).describe("heights in the 'profile' output");
    d.param_float("dz", 40).range(1e-3, 1e5).with_unit("m").describe("spacing of the 'profile' heights");
}

void cook(CookContext& ctx) {
    sim::Sounding s;
    read_options(ctx, sim::sounding_options(), s);
    const int levels = int(ctx.get_int("levels"));
    const double dz = ctx.get_float("dz");
    s.validate();
    const sim::ReferenceProfile ref = sim::make_reference(s, levels, dz);
    auto profile = ctx.make_field2d({{1, levels}}, 6, Box2d{{{0, 0}}, {{dz, levels * dz}}},
                                    {"theta", "temperature", "pressure", "rho", "qv", "rh"});
    for (int k = 0; k < levels; ++k) {
        const size_t i = size_t(k);
        profile->channel(0)[i] = float(ref.theta[i]);
        profile->channel(1)[i] = float(ref.theta[i] * ref.exner[i]);
        profile->channel(2)[i] = float(ref.pressure[i]);
        profile->channel(3)[i] = float(ref.rho[i]);
        profile->channel(4)[i] = float(ref.qv[i]);
        profile->channel(5)[i] = float(s.total_water > 0 ? 1.0 : s.rh_at((k + 0.5) * dz));
    }
    ctx.set_output("out", Field2DPtr(std::make_shared<Field2D>(sim_nodes::sounding_record(s))));
    ctx.set_output("profile", Field2DPtr(std::move(profile)));
}
} // namespace

ATLAS_REGISTER_NODE(registry) {
    registry.add({.name = "sim/sounding", .version = 1, .declare = declare, .cook = cook});
}

// sim/sounding: the ambient atmosphere the cloud grows in (lapse rates, capping
// inversion, humidity profile), as a record for sim/cloud_growth plus its
// hydrostatic profile for inspection.
#include "atlas/sim/simulation.h"
#include "sim_params.h"

#include <cmath>

namespace {
using namespace atlas;

void declare(NodeDeclaration& d) {
    d.doc("Ambient sounding for sim/cloud_growth: potential temperature with a lapse rate, a capping inversion (height, "
          "jump, depth) and a relative-humidity profile; or, with total_water > 0, a saturated moist-neutral atmosphere. "
          "'out' is the parameter record (1 x 1, one channel per member, see docs/solver.md); 'profile' is the hydrostatic "
          "reference at 'levels' heights dz apart (channels theta K, temperature K, pressure Pa, rho kg/m^3, qv kg/kg, rh).");
    d.output("out", PortType::Field2D, "sounding record for sim/cloud_growth's 'sounding' input");
    d.output("profile", PortType::Field2D, "1 x levels: theta, temperature, pressure, rho, qv, rh at cell-centre heights");
    d.param_float("surface_pressure", 1.0e5).range(3e4, 1.2e5).with_unit("Pa").describe("pressure at the grid bottom");
    d.param_float("surface_theta", 300).range(200, 400).with_unit("K").describe("potential temperature at the grid bottom");
    d.param_float("theta_lapse", 0.003).range(0, 0.05).with_unit("K/m").describe("dtheta/dz below the inversion (0 = neutral)");
    d.param_float("inversion_height", 2500).range(0, 1e9).with_unit("m").describe("base of the capping inversion (1e9 = none)");
    d.param_float("inversion_jump", 4).range(0, 20).with_unit("K").describe("theta increase across the inversion");
    d.param_float("inversion_depth", 200).range(1, 2000).with_unit("m").describe("depth over which the jump is spread");
    d.param_float("theta_lapse_above", 0.004).range(0, 0.05).with_unit("K/m").describe("dtheta/dz above the inversion");
    d.param_float("surface_rh", 0.85).range(0, 1).describe("relative humidity at the ground");
    d.param_float("rh_lapse", -1e-4).range(-1e-3, 1e-3).with_unit("1/m").describe("RH change per metre below the inversion");
    d.param_float("rh_above", 0.3).range(0, 1).describe("relative humidity above the inversion");
    d.param_float("total_water", 0).range(0, 0.05).with_unit("kg/kg")
        .describe("> 0: saturated moist-neutral atmosphere with this total water (surface_theta is then theta_l; lapse and RH ignored)");
    d.param_int("levels", 64).range(1, 4096).describe("heights in the 'profile' output");
    d.param_float("dz", 40).range(1e-3, 1e5).with_unit("m").describe("spacing of the 'profile' heights");
}

void cook(CookContext& ctx) {
    sim::Sounding s;
    const auto& names = sim_nodes::sounding_channels();
    const auto members = sim_nodes::sounding_members(s);
    for (size_t c = 0; c < names.size(); ++c) *members[c] = ctx.get_float(names[c]);
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

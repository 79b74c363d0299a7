// The Sounding option schema (atlas/sim/sounding_options.h).
#include "atlas/sim/sounding_options.h"

namespace atlas::sim {

std::span<const NumberOption<Sounding>> sounding_options() {
    using S = Sounding;
    static const NumberOption<S> options[] = {
        {"surface_pressure", &S::surface_pressure, 3e4, 1.2e5, "Pa", "pressure at the grid bottom"},
        {"surface_theta", &S::surface_theta, 200, 400, "K", "potential temperature at the grid bottom"},
        {"theta_lapse", &S::theta_lapse, 0, 0.05, "K/m", "dtheta/dz below the inversion (0 = neutral)"},
        {"inversion_height", &S::inversion_height, 0, 1e9, "m", "base of the capping inversion (1e9 = none)"},
        {"inversion_jump", &S::inversion_jump, 0, 20, "K", "theta increase across the inversion"},
        {"inversion_depth", &S::inversion_depth, 1, 2000, "m", "depth over which the jump is spread"},
        {"theta_lapse_above", &S::theta_lapse_above, 0, 0.05, "K/m", "dtheta/dz above the inversion"},
        {"surface_rh", &S::surface_rh, 0, 1, "", "relative humidity at the ground"},
        {"rh_lapse", &S::rh_lapse, -1e-3, 1e-3, "1/m", "RH change per metre below the inversion"},
        {"rh_above", &S::rh_above, 0, 1, "", "relative humidity above the inversion"},
        {"total_water", &S::total_water, 0, 0.05, "kg/kg",
         "> 0: saturated moist-neutral atmosphere with this total water (surface_theta is then theta_l; lapse and RH ignored)"},
    };
    return options;
}

Sounding capped_boundary_layer_sounding() {
    Sounding s;
    s.theta_lapse = 0.003;
    s.inversion_height = 2500;
    s.inversion_jump = 4;
    s.inversion_depth = 200;
    s.theta_lapse_above = 0.004;
    s.surface_rh = 0.85;
    s.rh_lapse = -1e-4;
    s.rh_above = 0.3;
    return s;
}

} // namespace atlas::sim

// atlas/sim/sim_options.h - the one schema of the solver options a graph sets
// (atlas/core/option_schema.h): the sim/cloud_growth node's parameters
// (declare_text_options / read_text_options) and the library's range checks
// (SimOptions::validate, KesslerOptions::validate, PressureSolver::project) are
// built from it, so they cannot drift apart.
#pragma once

#include "atlas/core/option_schema.h"
#include "atlas/sim/simulation.h"

#include <span>
#include <string_view>

namespace atlas::sim {

// In the sim/cloud_growth node's parameter order: cfl, time_scheme,
// step_error_tolerance, max_substeps, scheme, advection_reflection,
// reversible_theta_e, rain, rain_autoconversion_rate,
// rain_autoconversion_threshold, rain_accretion_rate, rain_evaporation,
// rain_sedimentation, anelastic, moist, pressure_tolerance,
// pressure_max_iterations, multigrid, condensation_rate, vorticity_confinement,
// viscosity, diffusivity.
// Names: rain_<member> fills SimOptions::kessler.<member> (KesslerOptions::validate
// checks those bounds), pressure_<member> and multigrid fill SimOptions::projection
// (PressureSolver::project checks them); the others are SimOptions' own members
// (SimOptions::validate). Defaults: SimOptions{}, read through each option's
// value_of. Not in it: wind (nz values; the node makes them from a ground wind and
// a shear, bounded by kSimMaxWind) and kessler.sedimentation_cfl (library only).
// Thread-safe (a static table).
std::span<const TextOption<SimOptions>> sim_options();

// The option named `name`; throws atlas::Error when there is none (a programming error).
const TextOption<SimOptions>& sim_option(std::string_view name);

} // namespace atlas::sim

// atlas/sim/sounding_options.h - the one schema of the Sounding members a graph
// sets (atlas/core/option_schema.h): Sounding::validate(), the sim/sounding node's
// parameters and its record's channels (nodes/sim/sim_params.h) are built from it.
#pragma once

#include "atlas/core/option_schema.h"
#include "atlas/sim/simulation.h"

#include <span>

namespace atlas::sim {

// Every Sounding member except theta_e (0 or [250, 400], checked by validate()),
// in member order - also the order of the sim/sounding record's channels.
// Defaults: Sounding{} (a dry neutral atmosphere without inversion).
std::span<const NumberOption<Sounding>> sounding_options();

// The sim/sounding node's defaults: a stable, moist boundary layer (theta lapse
// 3 K/km, RH 0.85 at the ground falling 0.1 per km) capped by a 4 K inversion at
// 2.5 km with drier (RH 0.3), more stable air above - a fair-weather cumulus day.
Sounding capped_boundary_layer_sounding();

} // namespace atlas::sim

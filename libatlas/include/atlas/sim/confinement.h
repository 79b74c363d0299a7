// atlas/sim/confinement.h - vorticity confinement (Fedkiw, Stam & Jensen 2001).
//
// f = eps dx |omega| (N x omega), N = grad|omega| / |grad|omega||, at cell
// centres, with omega = curl u from the cell-centred velocity (central
// differences, one-sided at the domain edges, wrapped along periodic axes);
// averaged to the interior faces (and the wrapped ones).
// Why the extra |omega|: the published form eps dx (N x omega) has units of m/s,
// so as an acceleration its eps is secretly a rate in 1/s; it amplifies
// grid-scale vortices at eps per second whatever the flow, which is mild for
// smoke at centimetre cells (dissipation ~ U/dx ~ 100/s) and a runaway at
// 30-100 m cloud cells (U/dx ~ 0.1/s): the cumulus graph's 50-130 m/s updrafts.
// Scaling by the local turnover rate |omega| makes eps dimensionless and the
// effect the same at any physical scale; it still vanishes as dx -> 0.
// eps in [0, 0.2]: with the second-order default time stepping (TimeScheme::
// Trapezoidal, less numerical dissipation) a 2 K test bubble at 47 m cells
// reaches 1.18x the eps = 0 updraft at 0.1, 1.9x at 0.2 and 3.7x at 0.3, so
// beyond 0.2 confinement outgrows the advection's dissipation (docs/solver.md).
// Deterministic for any thread count; not thread-safe on the same velocity.
#pragma once

#include "atlas/sim/mac_grid.h"

#include <vector>

namespace atlas::sim {

// Cell-centred confinement acceleration in m/s^2 (eps dimensionless, dx in m,
// omega in 1/s) for velocity `vel` (m/s); fx, fy, fz are resized to
// spec.cells(). eps >= 0. N is set to 0 where |grad|omega|| is below
// 1e-4 |omega| / dx (flat |omega|: the direction is round-off, not a vortex edge).
void confinement_force(const MacVelocity& vel, double eps, std::vector<float>& fx, std::vector<float>& fy,
                       std::vector<float>& fz);

// vel += dt * f on the interior faces (the mean of the two cells' forces).
void add_confinement(MacVelocity& vel, double eps, double dt);

} // namespace atlas::sim

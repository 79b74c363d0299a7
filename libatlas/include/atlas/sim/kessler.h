// atlas/sim/kessler.h - Kessler (1969) warm rain in the Klemp & Wilhelmson
// (1978) form: cloud water qc turns into rain qr by autoconversion and
// accretion, rain evaporates in subsaturated air, and rain falls at its
// terminal speed, leaving through the floor.
//
//   autoconversion  A = k1 (qc - a)+                   k1 = 1e-3 1/s, a = 1e-3 kg/kg
//   accretion       C = k2 qc qr^0.875                 k2 = 2.2 1/s
//   evaporation     E = (1/rho) (1 - qv/qvs) c_v (rho qr)^0.525 / (5.4e5 + 2.55e6 / (p qvs))
//                   c_v = 1.6 + 124.9 (rho qr)^0.2046  (rho in g/cm^3, p in mb, E in 1/s)
//   fall speed      V = 36.34 (rho qr)^0.1364 sqrt(rho_surface / rho)   (m/s, rho in g/cm^3)
//
// Units: theta in K, mixing ratios in kg/kg, pressure in Pa, density in
// kg/m^3 (converted internally where the fits need cgs), dt in s.
// Stiffness: over one dt, qc follows the exact solution of
// dqc/dt = -(k1 + k2 qr^0.875) qc + k1 a (qr frozen), so any rate x dt lands
// between qc and its equilibrium (never negative); evaporation is capped by qr
// and by the saturation deficit (linearised in T); sedimentation is upwind in
// flux form with ceil(V dt / (cfl dz)) substeps, so it conserves
// sum(rho qr dz) + fallout to float rounding at any dt.
// All functions are pure over their arguments; parallel loops write disjoint
// z-slices and sums are added in slice order (same bytes for any thread count).
#pragma once

#include "atlas/sim/mac_grid.h"

#include <span>
#include <vector>

namespace atlas::sim {

// Bounds, units and docs of the first five: the rain_* options of sim::sim_options()
// (sim_options.h), which validate() checks.
struct KesslerOptions {
    double autoconversion_rate = 1e-3;      // k1, 1/s
    double autoconversion_threshold = 1e-3; // a, kg/kg
    double accretion_rate = 2.2;            // k2, 1/s
    bool evaporation = true;
    bool sedimentation = true;
    double sedimentation_cfl = 0.9;         // cells per sedimentation substep, (0, 1]
    // Throws atlas::Error naming the member out of range.
    void validate() const;
};

// What one call did, summed over cells in kg/kg (x cells) unless stated.
struct KesslerReport {
    double autoconverted = 0, accreted = 0, evaporated = 0;
    double fallout = 0;          // kg of water that left through the floor (rho qr V dt dx^2, summed)
    int sedimentation_substeps = 0;
    double max_fall_speed = 0;   // m/s
};

// Terminal fall speed of rain (m/s) for rain mixing ratio qr (kg/kg) at
// density rho (kg/m^3), with the surface density rho_surface (kg/m^3).
double rain_fall_speed(double qr, double rho, double rho_surface);
// Klemp-Wilhelmson rain evaporation rate (kg/kg/s, >= 0; 0 when saturated).
double rain_evaporation_rate(double qv, double qr, double qvs, double rho, double p);

// Autoconversion, accretion and (optionally) evaporation over dt on a grid of
// `spec` (x fastest). pressure/exner/rho: nz reference values per cell row.
// theta gains -L_v E dt / (c_p Pi) where rain evaporates.
KesslerReport kessler_conversions(const GridSpec& spec, std::span<float> theta, std::span<float> qv,
                                  std::span<float> qc, std::span<float> qr, const std::vector<double>& pressure,
                                  const std::vector<double>& exner, const std::vector<double>& rho, double dt,
                                  const KesslerOptions& options);

// Rain falls by upwind flux-form transport over dt: rho_k qr_k changes by the
// flux rho V qr through its top and bottom faces; the bottom face of row 0 is
// the floor (rain leaves, counted in `fallout`, kg, with cell area dx^2).
KesslerReport rain_sedimentation(const GridSpec& spec, std::span<float> qr, const std::vector<double>& rho, double dt,
                                 const KesslerOptions& options);

} // namespace atlas::sim

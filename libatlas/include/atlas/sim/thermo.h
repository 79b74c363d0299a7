// atlas/sim/thermo.h - moist thermodynamics of the cloud solver.
//
// Units: temperature and potential temperature in K, pressure in Pa, mixing
// ratios in kg/kg, heights in m. Saturation vapour pressure by Bolton (1980):
//   e_s(T) = 611.2 Pa * exp(17.67 (T - 273.15) / (T - 29.65)),
// saturation mixing ratio q_s = eps e_s / (p - e_s) with e_s capped at p/2
// (keeps q_s finite at any temperature). Condensation is a saturation
// adjustment: the condensed amount d solves
//   qv - d = q_s(T + (L_v / c_p) d, p),   -qc <= d <= qv
// by safeguarded Newton iteration (bisection fallback), i.e. to equilibrium,
// so no time step or rate can overshoot. theta changes by L_v d / (c_p Pi),
// which conserves the liquid-water potential temperature
// theta_l = theta - L_v qc / (c_p Pi) exactly; qv + qc is conserved exactly
// (up to float rounding). All functions are pure and thread-safe.
#pragma once

namespace atlas::sim {

inline constexpr double kGravity = 9.81;    // m/s^2
inline constexpr double kRd = 287.04;       // J/(kg K), dry air
inline constexpr double kRv = 461.5;        // J/(kg K), water vapour
inline constexpr double kCp = 1004.5;       // J/(kg K), dry air at constant pressure
inline constexpr double kLv = 2.5e6;        // J/kg, latent heat of vaporisation
inline constexpr double kP00 = 1.0e5;       // Pa, reference pressure of theta
inline constexpr double kEps = kRd / kRv;   // 0.622

// Bolton (1980) saturation vapour pressure over liquid, Pa. T in [150, 400] K
// is the meaningful range; outside it the formula is still finite for T > 30 K.
double saturation_vapor_pressure(double T);
// Saturation mixing ratio, kg/kg, at temperature T (K) and pressure p (Pa, > 0).
double saturation_mixing_ratio(double T, double p);
// Exner function Pi = (p / p00)^(Rd/cp).
double exner(double p);

// Equivalent potential temperature of saturated air, Bryan & Fritsch (2002)
// eq. (6) form with constant L_v: theta_e = T (p_d/p00)^(-R_d/c) exp(L_v qv / (c T)),
// c = c_pd + c_l qt, c_l = 4186 J/(kg K), p_d = p qv-free partial pressure. K.
double equivalent_potential_temperature(double T, double p, double qv, double qt);

struct AdjustResult {
    double theta = 0, qv = 0, qc = 0;
    double condensed = 0; // d, kg/kg (negative = evaporated)
    int iterations = 0;
};

// Temperature (K) at which a parcel with vapour qv and total water qt at
// pressure p has the given equivalent potential temperature (the formula
// above; strictly increasing in T). Newton kept inside [100, 500] K.
double temperature_from_theta_e(double theta_e, double p, double qv, double qt);

// Equilibrium temperature (K) of total water qt at pressure p with the given
// theta_e: theta_e(T, p, min(qt, q_s(T, p)), qt) = theta_e. T_guess starts
// the safeguarded Newton iteration (bracket [100, 500] K).
double equilibrium_temperature_theta_e(double theta_e, double p, double qt, double T_guess);

// Bryan & Fritsch (2002) reversible adjustment: the parcel goes to
// equilibrium (qv = min(qt, q_s(T, p)), qc = qt - qv) keeping its equivalent
// potential temperature theta_e(T, p, qv, qt) (c = c_pd + c_l qt: the heat
// capacity of the liquid is counted) and qt = qv + qc exactly. `relax` as
// below (the condensed amount is relaxed, T follows from theta_e). Throws
// atlas::Error on non-finite input or p <= 0. Pure, thread-safe.
AdjustResult saturation_adjust_theta_e(double theta, double qv, double qc, double p, double relax = 1.0);

// Saturation adjustment of one parcel to equilibrium (see the file comment).
// `relax` in [0, 1] is the fraction of the way to equilibrium taken this step:
// 1 - exp(-rate * dt) for a finite condensation rate (1 = instantaneous).
// Any relax in [0, 1] keeps qv, qc >= 0 and lands between the old state and
// equilibrium, so a stiff rate x dt cannot overshoot. Throws atlas::Error on
// non-finite input or p <= 0.
AdjustResult saturation_adjust(double theta, double qv, double qc, double p, double relax = 1.0);

} // namespace atlas::sim

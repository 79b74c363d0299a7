// atlas/sim/simulation.h - the cloud-growth solver as an object an editor steps.
//
// Equations (anelastic; Boussinesq when `anelastic` is false), z up:
//   du/dt + (u.grad)u = -grad(p'/rho0) + b z + f_vc + nu lap u
//   div(rho0(z) u) = 0                    (Boussinesq: div u = 0)
//   dtheta/dt + u.grad theta = S_theta + L_v C / (c_p Pi0) + kappa lap theta'
//   dqv/dt + u.grad qv = S_qv - C,   dqc/dt + u.grad qc = C
//   b = g (theta_v - theta_v0) / theta_v0,  theta_v = theta (1 + 0.608 qv - qc)
// with the hydrostatic reference theta0(z), qv0(z), Pi0(z), p0(z), rho0(z)
// from an ambient Sounding, and the condensation C by saturation adjustment
// (thermo.h). Per substep: advect (u, theta, qv, qc[, qr]), add sources,
// saturation adjustment, optional Kessler rain (kessler.h; qr loads the
// buoyancy and falls out through the floor), buoyancy / vorticity confinement /
// diffusion, pressure projection. Optional Bryan & Fritsch reversible
// thermodynamics (SimOptions::reversible_theta_e) advect and conserve theta_e.
// Time steps are CFL-adaptive; a requested dt is split into equal substeps,
// at most `max_substeps` of them, else step() throws atlas::Error.
// Determinism: same inputs, same bytes for any TBB thread count.
// A Simulation is not thread-safe; its outputs are independent values.
#pragma once

#include "atlas/core/field.h"
#include "atlas/sim/advection.h"
#include "atlas/sim/kessler.h"
#include "atlas/sim/pressure.h"

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace atlas::sim {

// Ambient atmosphere. Heights from the grid bottom (z = 0), in metres.
struct Sounding {
    double surface_pressure = 1.0e5; // Pa, [3e4, 1.2e5]
    double surface_theta = 300.0;    // K, [200, 400]
    double theta_lapse = 0.0;        // dtheta/dz below the inversion, K/m, [0, 0.05] (0 = neutral)
    double inversion_height = 1e9;   // m, base of the capping inversion (1e9 = none)
    double inversion_jump = 0.0;     // K added across the inversion, [0, 20]
    double inversion_depth = 200.0;  // m, [1, 2000], the jump is spread over it
    double theta_lapse_above = 0.0;  // K/m above the inversion, [0, 0.05]
    double surface_rh = 0.0;         // relative humidity at z = 0, [0, 1]
    double rh_lapse = 0.0;           // RH change per metre below the inversion, [-1e-3, 1e-3]
    double rh_above = 0.0;           // RH above the inversion, [0, 1]
    // > 0: a saturated, moist-neutral atmosphere with this total water (kg/kg,
    // [0, 0.05]) at every height; surface_theta is then the surface liquid-water
    // potential temperature theta_l; the profile follows the solver's own
    // reversible moist adiabat (theta kept, adjusted at each cell's pressure),
    // and the RH and lapse members are ignored (the Bryan & Fritsch moist case).
    double total_water = 0.0;

    // > 0 together with total_water: the Bryan & Fritsch (2002) moist-neutral
    // sounding instead: every level saturated with this equivalent potential
    // temperature (K, [250, 400]; thermo.h formula, c_pd + c_l q_t) and
    // total_water, integrated hydrostatically with the density potential
    // temperature theta_rho = theta (1 + qv / eps) / (1 + q_t); surface_theta is
    // then ignored. Use with SimOptions::reversible_theta_e.
    double theta_e = 0;

    // Throws atlas::Error naming the member out of range.
    void validate() const;
    double theta_at(double z) const;
    double rh_at(double z) const;
};

// Reference profile at cell centres (nz entries each) from a Sounding by
// hydrostatic integration dPi/dz = -g / (c_p theta0).
struct ReferenceProfile {
    std::vector<double> theta, qv, qc, exner, pressure, rho;
};
ReferenceProfile make_reference(const Sounding& s, int nz, double dx);

// A heated, moist ground patch whose strength is modulated by value noise
// from hash_coords(seed, ...): deterministic and resolution-independent.
struct GroundPatch {
    double center_x = 0, center_y = 0; // m, in grid coordinates (min corner = 0)
    double radius = 500;               // m, > 0
    double depth = 200;                // m above ground that is heated, > 0
    double heat_rate = 0.01;           // K/s at the centre, [-10, 10] (< 0: a cooling patch)
    double vapour_rate = 0.0;          // kg/kg/s at the centre, [0, 1e-3]
    double noise_scale = 200;          // m, feature size of the modulation, > 0
    double noise_amount = 0.5;         // 0 = smooth patch, 1 = fully noise-modulated
    uint32_t seed = 1;
};

// How the operators of one substep are combined in time.
//   Split: advect with u^n (frozen), then sources, buoyancy, diffusion and the
//     projection at the arrival point: first order in dt (the pressure, the
//     forces and the trajectory are all off-centred by dt/2).
//   Trapezoidal: second order in dt. Forces are split half at the departure
//     point and half at the arrival point (semi-Lagrangian trapezoidal rule:
//     q^{n+1} = A[q + dt/2 F]^n + dt/2 F^{n+1}); the pressure half of it is the
//     previous projection's removed gradient (dt/2 grad p^n, rescaled to the new
//     dt) taken off before advecting; back-traces use the time-centred velocity
//     u^n + (dt / (2 dt_prev)) (u^n - u^{n-1}); explicit diffusion at the
//     arrival point is a two-stage (Heun) evaluation. One projection per
//     substep, like Split; costs kSimTrapezoidalBytesPerCell and ~10 % time.
//     The first substep after construction or after velocity() was taken
//     mutably has no history and is first order (a start-up step).
enum class TimeScheme { Split, Trapezoidal };

// The defaults are the member initializers; every member a graph sets has its
// bounds, unit and doc in the schema sim::sim_options() (sim_options.h), which
// validate() checks and the sim/cloud_growth node declares.
struct SimOptions {
    bool anelastic = true;                // false: Boussinesq (rho0 = const)
    bool moist = true;                    // false: dry (qv, qc stay passive)
    AdvectionScheme scheme = AdvectionScheme::MacCormack;
    TimeScheme time_scheme = TimeScheme::Trapezoidal; // ignored when advection_reflection is on
    double cfl = 1.0;                     // max cells travelled per substep
    // Accuracy-based step control (Trapezoidal only; 0 = off): the embedded
    // estimate of the back-trace error, max |u_trace - (u^n + u^{n+1}) / 2| dt / dx
    // (cells; O(dt^3)), is kept below this by limiting the next substep to
    // 0.9 dt (tol / err)^(1/3) (at most 2x the last substep); a start-up
    // substep (no history) is kept to sqrt(2 tol dx / max|b|). In cells.
    // Off by default: at CFL 1 the Trapezoidal peak w of a density current is
    // within 1 % of the time-converged value (docs/solver.md); 0.02 is the
    // setting measured there for sharp fronts at larger CFL.
    double step_error_tolerance = 0.0;
    int max_substeps = 64;
    double condensation_rate = 0;         // 1/s; 0 = instantaneous equilibrium, else relax 1 - exp(-rate dt)
    double vorticity_confinement = 0;     // epsilon, dimensionless (confinement.h; at 0.1 a test bubble's max w is 1.14-1.18x the eps = 0 run)
    double viscosity = 0;                 // nu, m^2/s (explicit; limits dt to dx^2/(8 nu))
    double diffusivity = 0;               // kappa for theta', qv, qc, m^2/s
    std::vector<double> wind;             // optional ambient u(z) per cell row (nz entries), m/s, |u| <= kSimMaxWind, relaxed to at open x faces
    ProjectionOptions projection;
    // Kessler warm rain (kessler.h): qr is advected, made from qc by
    // autoconversion and accretion, evaporates in subsaturated air, loads the
    // buoyancy and falls out through the floor. Off by default (needs moist);
    // adds kSimRainBytesPerCell.
    bool rain = false;
    KesslerOptions kessler;
    // Bryan & Fritsch (2002) reversible thermodynamics: the saturation
    // adjustment keeps theta_e (saturation_adjust_theta_e: heat capacity of the
    // liquid counted) instead of the linearised theta_l. StepReport's
    // theta_l_drift then measures the difference between the two. Default off.
    bool reversible_theta_e = false;
    // Advection-reflection time stepping (Zehnder et al. 2018): two half-step
    // projections per substep, the first one's removed part reflected; keeps the
    // kinetic energy the plain advect-project split loses at large CFL. Costs a
    // second projection and 12 B/cell (kSimReflectionBytesPerCell). Default off.
    // Bryan & Fritsch dry at 100 m, dt 5 s: max w 12.9 -> 14.3 m/s (paper 14.5).
    bool advection_reflection = false;
    // Throws atlas::Error naming the member out of range.
    void validate(int nz) const;
};

// Bound of |SimOptions::wind| (m/s), also of the sim/cloud_growth node's ground wind.
constexpr double kSimMaxWind = 200;

// Extra bytes per cell with TimeScheme::Trapezoidal (without advection_reflection):
// the previous velocity u^{n-1} and the projection's removed gradient (two MAC velocities).
constexpr uint64_t kSimTrapezoidalBytesPerCell = 24;
// Extra bytes per cell when options.rain is on: qr and its advection output.
constexpr uint64_t kSimRainBytesPerCell = 8;
// Extra bytes per cell with options.advection_reflection: a third MAC velocity.
constexpr uint64_t kSimReflectionBytesPerCell = 12;
// simulation_bytes(spec) plus the rain fields / reflection velocity when on.
uint64_t simulation_bytes(const GridSpec& spec, const SimOptions& options);

// What one call of step() did.
struct StepReport {
    double dt = 0;            // s, total advanced
    int substeps = 0;
    double substep_dt = 0;    // s
    int pressure_iterations = 0;     // summed over substeps
    int max_pressure_iterations = 0; // worst substep
    bool pressure_converged = true;
    DivergenceStats divergence;      // after the last projection, 1/s
    double total_water = 0;          // sum of qv + qc + qr over cells (kg/kg * cells) after the step
    double water_mass = 0;           // kg: sum of rho0 (qv + qc + qr) dx^3 after the step
    double rain_fallout = 0;         // kg of rain that left through the floor during the step (0 without rain)
    double autoconverted = 0, accreted = 0, rain_evaporated = 0; // kg/kg summed over cells, this step
    double max_qr = 0;               // kg/kg
    int sedimentation_substeps = 0;  // summed over substeps
    // Embedded time-step error estimate (Trapezoidal): worst over the substeps of
    // max |u_trace - (u^n + u^{n+1}) / 2| dt / dx, cells; 0 with Split.
    double step_error = 0;
    double accuracy_dt = 0;          // s, the accuracy limit on the next substep (0 = none)
    const char* dt_limit = "";       // what split the step into substeps: "step" (none), "cfl", "buoyancy", "diffusion", "accuracy"
    // Vapour sinks (negative source rates) asked for more vapour than a cell
    // held; only what was there was taken. kg/kg summed over cells, this step.
    double vapour_sink_deficit = 0;
    // Negative qv / qc / qr made by the explicit diffusion, set to 0 and taken
    // back from the positive cells of the same z-slice in proportion (so the
    // slice's water is conserved). kg/kg summed over cells, this step.
    double water_redistributed = 0;
    double water_drift = 0;          // relative change of total water by the saturation adjustment (should be ~1e-7)
    double theta_l_drift = 0;        // max |delta theta_l| across the adjustment, K
    double condensed = 0;            // net condensation in the step, kg/kg summed over cells
    double max_w = 0, max_speed = 0; // m/s
    double max_theta_perturbation = 0, min_theta_perturbation = 0; // K, theta - theta0
    double max_qc = 0;               // kg/kg
    double seconds_advect = 0, seconds_sources = 0, seconds_thermo = 0, seconds_forces = 0, seconds_project = 0;
    double seconds_rain = 0;
    // {"dt":..,"substeps":..,...} one JSON object.
    std::string to_json() const;
};

class Simulation {
public:
    // Allocates the state after checking simulation_bytes(spec) against `budget`
    // (when given). State starts at rest in the reference atmosphere.
    Simulation(const GridSpec& spec, const Sounding& sounding, const SimOptions& options,
               const MemoryBudget* budget = nullptr);
    ~Simulation();

    const GridSpec& spec() const { return spec_; }
    const ReferenceProfile& reference() const { return ref_; }
    double time() const { return time_; }

    // Mutable state (for set-up and art direction between steps). Cell arrays
    // have spec().cells() entries, x fastest. Negative qv, qc or qr in the
    // state is refused by step() (atlas::Error naming the field and cell).
    // Taking the velocity mutably drops the Trapezoidal history (the next
    // substep is a first-order start-up step).
    MacVelocity& velocity() {
        history_dt_ = 0;
        return vel_;
    }
    std::vector<float>& theta() { return theta_; } // full potential temperature, K
    std::vector<float>& qv() { return qv_; }
    std::vector<float>& qc() { return qc_; }
    std::vector<float>& qr() { return qr_; } // rain, kg/kg; empty unless options.rain
    const MacVelocity& velocity() const { return vel_; }
    const std::vector<float>& theta() const { return theta_; }
    const std::vector<float>& qv() const { return qv_; }
    const std::vector<float>& qc() const { return qc_; }
    const std::vector<float>& qr() const { return qr_; }

    // Adds a potential-temperature perturbation (K) to every cell.
    void add_theta(const std::vector<float>& delta);
    // Continuous sources, per second: heat (K/s) and vapour (kg/kg/s) per
    // cell. Field3D overloads need the grid's resolution and 1 channel.
    // Throws atlas::Error naming `what` when a value is NaN/Inf or sizes differ.
    void set_sources(std::vector<float> heat_rate, std::vector<float> vapour_rate, const std::string& what = "sources");
    void set_sources(const Field3D& heat_rate, const Field3D& vapour_rate, const std::string& what = "sources");
    void add_ground_patch(const GroundPatch& patch);

    // Advances by dt seconds (> 0) in equal CFL-limited substeps.
    StepReport step(double dt);

    // Outputs as cell-centred Field3D over [0, n dx] (world metres).
    Field3D cloud_water() const;   // "qc", kg/kg
    Field3D temperature() const;   // "T", K (theta * Pi0)
    Field3D theta_perturbation() const; // "theta_p", K
    Field3D vapour() const;        // "qv", kg/kg
    Field3D rain_water() const;    // "qr", kg/kg (zeros without rain)
    Field3D velocity_field() const; // "u","v","w" at cell centres, m/s

private:
    void substep(double dt, StepReport& rep);
    void substep_trapezoidal(double dt, StepReport& rep);
    void advect_scalars(const MacVelocity& vel, const Lattice& cl, double dt);
    void buoyancy(double dt) { buoyancy_into(vel_, dt); }
    void buoyancy_into(MacVelocity& v, double dt);
    void add_sources(double dt, StepReport& rep);
    void thermodynamics(double dt, StepReport& rep);
    void confinement(double dt);
    void diffuse(double dt);
    double max_buoyancy() const;

    GridSpec spec_;
    SimOptions opt_;
    ReferenceProfile ref_;
    std::vector<double> thetav0_;
    PressureSolver solver_;
    MacVelocity vel_, vel_tmp_, vel_third_;
    MacVelocity vel_prev_, grad_; // Trapezoidal: u^{n-1}; the last projection's removed part (dt/2 grad p)
    double history_dt_ = 0;       // dt of the substep that made vel_prev_ / grad_ (0 = no history)
    double last_error_ = 0, last_dt_ = 0; // step control: the last substep's error estimate and dt
    std::vector<float> theta_, qv_, qc_, qr_, tmp_;
    std::vector<float> scalar_tmp_[3];                 // advection outputs, swapped with the state
    std::unique_ptr<AdvectionScratch> scratch_;        // back-traces kept between steps
    std::vector<float> heat_src_, vap_src_;
    double time_ = 0;
};

} // namespace atlas::sim

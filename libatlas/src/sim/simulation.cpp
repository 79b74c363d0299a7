// The cloud-growth Simulation: sounding, sources, forces, stepping (see simulation.h).
#include "atlas/core/progress.h"
#include "atlas/sim/simulation.h"
#include "atlas/sim/sim_options.h"
#include "atlas/sim/sounding_options.h"

#include "atlas/core/error.h"
#include "atlas/core/hash.h"
#include "atlas/sim/confinement.h"
#include "atlas/sim/thermo.h"

#include "atlas/core/parallel.h"
#include "atlas/noise/value_fbm.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

namespace atlas::sim {
namespace {

using Clock = std::chrono::steady_clock;


void check_range(double v, double lo, double hi, const char* what) {
    if (!(v >= lo && v <= hi)) {
        char buf[256];
        std::snprintf(buf, sizeof buf, "sim: %s = %g, expected %g..%g", what, v, lo, hi);
        throw Error(buf);
    }
}

void check_nonnegative(const std::vector<float>& a, const char* what) {
    for (size_t n = 0; n < a.size(); ++n)
        if (a[n] < 0)
            throw Error(std::string("sim step: ") + what + " = " + std::to_string(a[n]) + " kg/kg at cell " + std::to_string(n) +
                        "; mixing ratios written into the state must be >= 0 (not clamped: that would add water)");
}

void check_finite(const std::vector<float>& a, const std::string& what) {
    for (size_t n = 0; n < a.size(); ++n)
        if (!std::isfinite(a[n])) throw Error("sim: " + what + " holds NaN/Inf at cell " + std::to_string(n));
}

} // namespace

void Sounding::validate() const {
    check_options(*this, sounding_options(), "sim: sounding"); // the ranges sim/sounding declares
    if (theta_e != 0) check_range(theta_e, 250, 400, "sounding.theta_e (K)");
    if (theta_e != 0 && !(total_water > 0)) throw Error("sim: sounding.theta_e needs sounding.total_water > 0");
}

double Sounding::theta_at(double z) const {
    double zi = inversion_height;
    if (z <= zi) return surface_theta + theta_lapse * z;
    double base = surface_theta + theta_lapse * zi;
    double dz = z - zi;
    double jump = inversion_jump * std::min(dz / inversion_depth, 1.0);
    return base + jump + theta_lapse_above * dz;
}

double Sounding::rh_at(double z) const {
    if (z > inversion_height) return rh_above;
    return std::clamp(surface_rh + rh_lapse * z, 0.0, 1.0);
}

ReferenceProfile make_reference(const Sounding& s, int nz, double dx) {
    s.validate();
    ReferenceProfile r;
    r.theta.resize(size_t(nz));
    r.qv.resize(size_t(nz));
    r.exner.resize(size_t(nz));
    r.pressure.resize(size_t(nz));
    r.rho.resize(size_t(nz));
    r.qc.assign(size_t(nz), 0.0);
    if (s.theta_e > 0) {
        // Bryan & Fritsch moist-neutral: theta_e and q_t constant, saturated;
        // dPi/dz = -g / (c_p theta_rho) by Heun's rule on 16 sub-steps per cell.
        const double qt = s.total_water;
        double T_guess = s.theta_e;
        auto state = [&](double pi_at, double& th, double& qv, double& qc) {
            const double p = kP00 * std::pow(pi_at, kCp / kRd);
            const double T = equilibrium_temperature_theta_e(s.theta_e, p, qt, T_guess);
            T_guess = T;
            qv = std::min(qt, saturation_mixing_ratio(T, p));
            qc = qt - qv;
            th = T / pi_at;
            return th * (1 + qv / kEps) / (1 + qt);
        };
        double pi = exner(s.surface_pressure), z = 0, th, qv, qc;
        for (int k = 0; k < nz; ++k) {
            const double zc = (k + 0.5) * dx;
            const int sub = 16;
            const double h = (zc - z) / sub;
            for (int m = 0; m < sub; ++m) {
                const double r1 = state(pi, th, qv, qc);
                const double pred = pi - kGravity / (kCp * r1) * h;
                if (!(pred > 0.05)) break;
                const double r2 = state(pred, th, qv, qc);
                pi -= 0.5 * kGravity / kCp * (1 / r1 + 1 / r2) * h;
            }
            z = zc;
            if (!(pi > 0.05)) throw Error("sim: the domain top reaches above the modelled atmosphere (Exner < 0.05); lower nz * dx");
            const double rho_theta = state(pi, th, qv, qc);
            const double p = kP00 * std::pow(pi, kCp / kRd);
            r.theta[size_t(k)] = th;
            r.qv[size_t(k)] = qv;
            r.qc[size_t(k)] = qc;
            r.exner[size_t(k)] = pi;
            r.pressure[size_t(k)] = p;
            r.rho[size_t(k)] = p / (kRd * rho_theta * pi); // p = rho R_d T_rho
        }
        return r;
    }
    const bool saturated = s.total_water > 0;
    // Hydrostatic: dPi/dz = -g / (cp theta), integrated with fine sub-steps (midpoint rule).
    double pi = exner(s.surface_pressure), z = 0;
    AdjustResult below{s.surface_theta, s.total_water, 0, 0, 0};
    if (saturated) below = saturation_adjust(s.surface_theta, s.total_water, 0, s.surface_pressure);
    double theta_below = below.theta;
    for (int k = 0; k < nz; ++k) {
        double zc = (k + 0.5) * dx;
        const int sub = 16;
        double h = (zc - z) / sub;
        for (int m = 0; m < sub; ++m) {
            double th = saturated ? theta_below : s.theta_at(z + (m + 0.5) * h);
            const double next = pi - kGravity / (kCp * th) * h;
            if (!(next > 0.05)) {
                // Where Exner reaches 0.05 (linear within the sub-step): the model top.
                const double ztop = z + m * h + h * (pi - 0.05) / (pi - next);
                char buf[400];
                std::snprintf(buf, sizeof buf,
                              "sim: the cell centre at z = %g m (row %d of nz = %d, dx = %g m) lies above the modelled "
                              "atmosphere, which ends where the Exner function falls to 0.05, at z = %.0f m for this "
                              "sounding; keep (nz - 1/2) dx below it (lower nz or dx)",
                              zc, k, nz, dx, ztop);
                throw Error(buf);
            }
            pi = next;
        }
        z = zc;
        double p = kP00 * std::pow(pi, kCp / kRd);
        double th, qv, qc = 0;
        if (saturated) {
            // The model's own reversible moist adiabat: the parcel from the cell
            // below keeps theta, qv, qc (as advection does) and is adjusted at this
            // cell's pressure (as the solver does), so the profile is neutral for it.
            AdjustResult a = saturation_adjust(below.theta, below.qv, below.qc, p);
            below = a;
            th = a.theta, qv = a.qv, qc = a.qc;
        } else {
            th = s.theta_at(zc);
            qv = s.rh_at(zc) * saturation_mixing_ratio(th * pi, p);
        }
        theta_below = th;
        double T = th * pi;
        r.theta[size_t(k)] = th;
        r.exner[size_t(k)] = pi;
        r.pressure[size_t(k)] = p;
        r.qv[size_t(k)] = qv;
        r.qc[size_t(k)] = qc;
        r.rho[size_t(k)] = p / (kRd * T * (1 + 0.608 * qv));
    }
    return r;
}

void SimOptions::validate(int nz) const {
    // The bounds sim/cloud_growth declares (sim_options.h), for SimOptions' own numbers;
    // the rain_* ones are KesslerOptions' (kessler.validate() below, only with rain), the
    // pressure_* ones ProjectionOptions' (checked by the pressure solver).
    for (const TextOption<SimOptions>& o : sim_options()) {
        const std::string_view name = o.name;
        if ((o.kind != OptionKind::Number && o.kind != OptionKind::Integer) || name.starts_with("rain_") || name.starts_with("pressure_"))
            continue;
        const std::string what = "options." + std::string(name) + (*o.unit ? std::string(" (") + o.unit + ")" : "");
        check_range(o.value_of(*this).number, o.min, o.max, what.c_str());
    }
    if (!wind.empty() && wind.size() != size_t(nz)) throw Error("sim: options.wind needs nz entries (one per cell row)");
    for (double w : wind) check_range(w, -kSimMaxWind, kSimMaxWind, "options.wind (m/s)");
    if (rain) kessler.validate();
    if (rain && !moist) throw Error("sim: options.rain needs options.moist");
}

uint64_t simulation_bytes(const GridSpec& spec, const SimOptions& options) {
    return simulation_bytes(spec) + (options.rain ? uint64_t(spec.cells()) * kSimRainBytesPerCell : 0) +
           (options.advection_reflection ? uint64_t(spec.cells()) * kSimReflectionBytesPerCell
            : options.time_scheme == TimeScheme::Trapezoidal ? uint64_t(spec.cells()) * kSimTrapezoidalBytesPerCell
                                                             : 0);
}

std::string StepReport::to_json() const {
    char buf[2048];
    std::snprintf(buf, sizeof buf,
                  "{\"dt\":%.9g,\"substeps\":%d,\"substep_dt\":%.9g,\"pressure_iterations\":%d,"
                  "\"max_pressure_iterations\":%d,\"pressure_converged\":%s,\"divergence_l2\":%.9g,"
                  "\"divergence_max\":%.9g,\"total_water\":%.9g,\"water_drift\":%.9g,\"theta_l_drift\":%.9g,"
                  "\"condensed\":%.9g,\"max_w\":%.9g,\"max_speed\":%.9g,\"max_theta_perturbation\":%.9g,"
                  "\"min_theta_perturbation\":%.9g,\"max_qc\":%.9g,\"seconds_advect\":%.6f,\"seconds_sources\":%.6f,"
                  "\"seconds_thermo\":%.6f,\"seconds_forces\":%.6f,\"seconds_project\":%.6f,\"water_mass\":%.9g,"
                  "\"rain_fallout\":%.9g,\"autoconverted\":%.9g,\"accreted\":%.9g,\"rain_evaporated\":%.9g,"
                  "\"max_qr\":%.9g,\"sedimentation_substeps\":%d,\"seconds_rain\":%.6f,\"step_error\":%.9g,"
                  "\"accuracy_dt\":%.9g,\"dt_limit\":\"%s\",\"vapour_sink_deficit\":%.9g,\"water_redistributed\":%.9g}",
                  dt, substeps, substep_dt, pressure_iterations, max_pressure_iterations,
                  pressure_converged ? "true" : "false", divergence.l2, divergence.max, total_water, water_drift,
                  theta_l_drift, condensed, max_w, max_speed, max_theta_perturbation, min_theta_perturbation, max_qc,
                  seconds_advect, seconds_sources, seconds_thermo, seconds_forces, seconds_project, water_mass,
                  rain_fallout, autoconverted, accreted, rain_evaporated, max_qr, sedimentation_substeps, seconds_rain,
                  step_error, accuracy_dt, dt_limit, vapour_sink_deficit, water_redistributed);
    return buf;
}

static GridSpec checked(const GridSpec& s, const SimOptions& o, const MemoryBudget* budget) {
    s.validate();
    if (budget)
        budget->check(simulation_bytes(s, o),
                      "sim: simulation state (" + std::to_string(simulation_bytes(s, o) / std::max<uint64_t>(s.cells(), 1)) +
                          " B/cell)");
    return s;
}

Simulation::Simulation(const GridSpec& spec, const Sounding& sounding, const SimOptions& options, const MemoryBudget* budget)
    : spec_(checked(spec, options, budget)), opt_(options), ref_(make_reference(sounding, spec.nz, spec.dx)),
      solver_(spec, options.anelastic ? ref_.rho : std::vector<double>{}), vel_(spec), vel_tmp_(spec),
      scratch_(std::make_unique<AdvectionScratch>()) {
    opt_.validate(spec.nz);
    const size_t n = spec.cells();
    theta_.resize(n);
    qv_.resize(n);
    qc_.assign(n, 0.f);
    if (opt_.rain) qr_.assign(n, 0.f);
    if (opt_.advection_reflection) vel_third_ = MacVelocity(spec);
    else if (opt_.time_scheme == TimeScheme::Trapezoidal) vel_prev_ = MacVelocity(spec), grad_ = MacVelocity(spec);
    tmp_.resize(n);
    heat_src_.assign(n, 0.f);
    vap_src_.assign(n, 0.f);
    thetav0_.resize(size_t(spec.nz));
    for (int k = 0; k < spec.nz; ++k) {
        thetav0_[size_t(k)] = ref_.theta[size_t(k)] * (1 + 0.608 * ref_.qv[size_t(k)] - ref_.qc[size_t(k)]);
        size_t base = size_t(k) * spec.nx * spec.ny;
        std::fill_n(qc_.begin() + long(base), size_t(spec.nx) * spec.ny, float(ref_.qc[size_t(k)]));
        std::fill_n(theta_.begin() + long(base), size_t(spec.nx) * spec.ny, float(ref_.theta[size_t(k)]));
        std::fill_n(qv_.begin() + long(base), size_t(spec.nx) * spec.ny, float(ref_.qv[size_t(k)]));
    }
    if (!opt_.wind.empty()) {
        for (int k = 0; k < spec.nz; ++k)
            for (int j = 0; j < spec.ny; ++j)
                for (int i = 0; i <= spec.nx; ++i) vel_.u[vel_.iu(i, j, k)] = float(opt_.wind[size_t(k)]);
        vel_.enforce_walls();
        solver_.project(vel_, opt_.projection);
    }
}

Simulation::~Simulation() = default;

void Simulation::add_theta(const std::vector<float>& delta) {
    if (delta.size() != theta_.size()) throw Error("sim add_theta: expected one value per cell");
    check_finite(delta, "add_theta");
    for (size_t n = 0; n < delta.size(); ++n) theta_[n] += delta[n];
}

void Simulation::set_sources(std::vector<float> heat, std::vector<float> vap, const std::string& what) {
    if (heat.empty()) heat.assign(theta_.size(), 0.f);
    if (vap.empty()) vap.assign(theta_.size(), 0.f);
    if (heat.size() != theta_.size() || vap.size() != theta_.size())
        throw Error("sim: " + what + ": source needs one value per cell (" + std::to_string(theta_.size()) + ")");
    check_finite(heat, what + " (heat rate)");
    check_finite(vap, what + " (vapour rate)");
    heat_src_ = std::move(heat);
    vap_src_ = std::move(vap);
}

void Simulation::set_sources(const Field3D& heat, const Field3D& vap, const std::string& what) {
    for (const Field3D* f : {&heat, &vap})
        if (f->nx() != spec_.nx || f->ny() != spec_.ny || f->nz() != spec_.nz || f->channels() < 1)
            throw Error("sim: " + what + ": source field resolution must match the grid");
    auto copy = [](const Field3D& f) { return std::vector<float>(f.channel(0).begin(), f.channel(0).end()); };
    set_sources(copy(heat), copy(vap), what);
}

void Simulation::add_ground_patch(const GroundPatch& g) {
    check_range(g.radius, 1e-3, 1e9, "ground_patch.radius (m)");
    check_range(g.depth, 1e-3, 1e9, "ground_patch.depth (m)");
    check_range(g.heat_rate, -10, 10, "ground_patch.heat_rate (K/s)");
    check_range(g.vapour_rate, 0, 1e-3, "ground_patch.vapour_rate (kg/kg/s)");
    check_range(g.noise_scale, 1e-3, 1e9, "ground_patch.noise_scale (m)");
    check_range(g.noise_amount, 0, 1, "ground_patch.noise_amount");
    check_range(g.center_x, -1e9, 1e9, "ground_patch.center_x (m)");
    check_range(g.center_y, -1e9, 1e9, "ground_patch.center_y (m)");
    const double h = spec_.dx;
    for (int k = 0; k < spec_.nz; ++k)
        for (int j = 0; j < spec_.ny; ++j)
            for (int i = 0; i < spec_.nx; ++i) {
                double x = (i + 0.5) * h, y = (j + 0.5) * h, z = (k + 0.5) * h;
                if (spec_.ny == 1) y = g.center_y;
                double ddx = x - g.center_x, ddy = y - g.center_y;
                // Periodic axes: the nearest image of the centre (the patch wraps).
                if (spec_.periodic(0)) ddx -= spec_.nx * h * std::round(ddx / (spec_.nx * h));
                if (spec_.periodic(1)) ddy -= spec_.ny * h * std::round(ddy / (spec_.ny * h));
                double r = std::hypot(ddx, ddy) / g.radius;
                if (r >= 1 || z > g.depth) continue;
                double shape = std::pow(std::cos(0.5 * M_PI * r), 2) * (1 - z / g.depth);
                double nse = noise::smooth_value_noise(g.seed, x / g.noise_scale, y / g.noise_scale, 0.0);
                double m = shape * ((1 - g.noise_amount) + g.noise_amount * 2 * nse);
                size_t c = vel_.ic(i, j, k);
                heat_src_[c] += float(g.heat_rate * m);
                vap_src_[c] += float(g.vapour_rate * m);
            }
}

double Simulation::max_buoyancy() const {
    double m = 0;
    for (int k = 0; k < spec_.nz; ++k) {
        size_t base = size_t(k) * spec_.nx * spec_.ny;
        for (size_t c = base; c < base + size_t(spec_.nx) * spec_.ny; ++c) {
            double tv = theta_[c] * (1 + 0.608 * qv_[c] - qc_[c] - (qr_.empty() ? 0.f : qr_[c]));
            m = std::max(m, std::fabs(kGravity * (tv - thetav0_[size_t(k)]) / thetav0_[size_t(k)]));
        }
    }
    return m;
}

void Simulation::buoyancy_into(MacVelocity& v, double dt) {
    const int nx = spec_.nx, ny = spec_.ny, nz = spec_.nz;
    std::vector<float>& b = tmp_;
    parallel_for_index(nz, [&](int k) {
        for (int j = 0; j < ny; ++j)
            for (int i = 0; i < nx; ++i) {
                size_t c = vel_.ic(i, j, k);
                double tv = double(theta_[c]) * (1 + 0.608 * qv_[c] - qc_[c] - (qr_.empty() ? 0.f : qr_[c]));
                b[c] = float(kGravity * (tv - thetav0_[size_t(k)]) / thetav0_[size_t(k)]);
            }
    });
    parallel_for_index(nz + 1, [&](int k) {
        for (int j = 0; j < ny; ++j)
            for (int i = 0; i < nx; ++i) {
                double bb = k == 0 ? b[vel_.ic(i, j, 0)] : k == nz ? b[vel_.ic(i, j, nz - 1)]
                                                                   : 0.5 * (b[vel_.ic(i, j, k - 1)] + b[vel_.ic(i, j, k)]);
                v.w[v.iw(i, j, k)] += float(dt * bb);
            }
    });
}

void Simulation::confinement(double dt) { add_confinement(vel_, opt_.vorticity_confinement, dt); }

namespace {
// out += coef_dt_h2 * lap(in - ref) on lattice l, zero-gradient edges (the
// mirror image across a free-slip wall / no-flux face), wrapped along periodic
// axes (index mod the period: on a face lattice the last sample is the first
// one's copy). out may not alias in.
void lap_accumulate(const Lattice& l, const std::vector<float>& in, std::vector<float>& out, double coef_dt_h2,
                    const std::vector<double>* ref_by_k) {
    auto wrap = [](int i, int p) { return i < 0 ? i + p : i >= p ? i - p : i; };
    auto at = [&](int i, int j, int k) {
        i = l.period[0] > 0 ? wrap(i, l.period[0]) : std::clamp(i, 0, l.n[0] - 1);
        j = l.period[1] > 0 ? wrap(j, l.period[1]) : std::clamp(j, 0, l.n[1] - 1);
        k = std::clamp(k, 0, l.n[2] - 1);
        double v = in[(size_t(k) * l.n[1] + j) * l.n[0] + i];
        return ref_by_k ? v - (*ref_by_k)[size_t(k)] : v;
    };
    parallel_for_index(l.n[2], [&](int k) {
        for (int j = 0; j < l.n[1]; ++j)
            for (int i = 0; i < l.n[0]; ++i) {
                double c = at(i, j, k);
                double lap = at(i - 1, j, k) + at(i + 1, j, k) + at(i, j - 1, k) + at(i, j + 1, k) + at(i, j, k - 1) +
                             at(i, j, k + 1) - 6 * c;
                out[(size_t(k) * l.n[1] + j) * l.n[0] + i] += float(coef_dt_h2 * lap);
            }
    });
}

// q += dt * coef * lap(q - ref) (forward Euler).
void diffuse_lattice(const Lattice& l, std::vector<float>& q, double coef_dt_h2, const std::vector<double>* ref_by_k) {
    const std::vector<float> src = q;
    lap_accumulate(l, src, q, coef_dt_h2, ref_by_k);
}

// The arrival half of the trapezoidal rule for explicit diffusion, a two-stage
// (Heun) evaluation: s = q + c lap q; q += c lap s, c = dt/2 * coef / dx^2.
void diffuse_heun(const Lattice& l, std::vector<float>& q, double coef_dt_h2, const std::vector<double>* ref_by_k,
                  std::vector<float>& scratch) {
    scratch = q;
    lap_accumulate(l, q, scratch, coef_dt_h2, ref_by_k);
    lap_accumulate(l, scratch, q, coef_dt_h2, ref_by_k);
}

// Sets negative values to 0 and takes the same amount from the positive cells
// of the same z-slice in proportion to their values, so each slice's sum is
// kept (to float rounding). A slice without enough positive water keeps its
// negatives clamped (counted all the same). Returns the amount moved.
double redistribute_negatives(std::vector<float>& q, int nz, size_t plane) {
    if (q.empty()) return 0;
    std::vector<double> moved(size_t(nz), 0.0);
    parallel_for_index(nz, [&](int k) {
        double neg = 0, pos = 0;
        for (size_t c = size_t(k) * plane; c < size_t(k + 1) * plane; ++c) {
            if (q[c] < 0) neg -= q[c];
            else pos += q[c];
        }
        if (neg == 0) return;
        const double scale = pos > neg ? (pos - neg) / pos : 0.0;
        for (size_t c = size_t(k) * plane; c < size_t(k + 1) * plane; ++c) q[c] = q[c] < 0 ? 0.f : float(q[c] * scale);
        moved[size_t(k)] = neg;
    });
    double t = 0;
    for (double m : moved) t += m;
    return t;
}
} // namespace

void Simulation::diffuse(double dt) {
    const double h2 = spec_.dx * spec_.dx;
    if (opt_.viscosity > 0) {
        diffuse_lattice(u_lattice(spec_), vel_.u, opt_.viscosity * dt / h2, nullptr);
        diffuse_lattice(v_lattice(spec_), vel_.v, opt_.viscosity * dt / h2, nullptr);
        diffuse_lattice(w_lattice(spec_), vel_.w, opt_.viscosity * dt / h2, nullptr);
        vel_.enforce_walls();
    }
    if (opt_.diffusivity > 0) {
        Lattice l = cell_lattice(spec_);
        diffuse_lattice(l, theta_, opt_.diffusivity * dt / h2, &ref_.theta);
        diffuse_lattice(l, qv_, opt_.diffusivity * dt / h2, &ref_.qv);
        diffuse_lattice(l, qc_, opt_.diffusivity * dt / h2, nullptr);
    }
}

void Simulation::add_sources(double dt, StepReport& rep) {
    const size_t plane = size_t(spec_.nx) * spec_.ny;
    std::vector<double> deficit(size_t(spec_.nz), 0.0);
    parallel_for_index(spec_.nz, [&](int k) {
        double d = 0;
        for (size_t c = size_t(k) * plane; c < size_t(k + 1) * plane; ++c) {
            theta_[c] += float(dt * heat_src_[c]);
            const float v = qv_[c] + float(dt * vap_src_[c]);
            if (v < 0) d -= v; // a sink takes only the vapour that is there
            qv_[c] = std::max(v, 0.f);
        }
        deficit[size_t(k)] = d;
    });
    for (double d : deficit) rep.vapour_sink_deficit += d;
}

void Simulation::thermodynamics(double dt, StepReport& rep) {
    const int nz = spec_.nz;
    const size_t plane = size_t(spec_.nx) * spec_.ny;
    auto t0 = Clock::now();
    if (opt_.moist) {
        const double relax = opt_.condensation_rate > 0 ? 1 - std::exp(-opt_.condensation_rate * dt) : 1.0;
        const size_t nzs = size_t(nz);
        std::vector<double> before(nzs), after(nzs), drift(nzs), cond(nzs);
        parallel_for_index(nz, [&](int k) {
            const double pi = ref_.exner[size_t(k)], p = ref_.pressure[size_t(k)], lk = kLv / (kCp * pi);
            double wb = 0, wa = 0, dr = 0, cd = 0;
            for (size_t c = size_t(k) * plane; c < size_t(k + 1) * plane; ++c) {
                wb += double(qv_[c]) + qc_[c];
                double thl0 = theta_[c] - lk * qc_[c];
                AdjustResult r = opt_.reversible_theta_e ? saturation_adjust_theta_e(theta_[c], qv_[c], qc_[c], p, relax)
                                                         : saturation_adjust(theta_[c], qv_[c], qc_[c], p, relax);
                float dq = float(r.condensed);
                dq = std::clamp(dq, -qc_[c], qv_[c]);
                qv_[c] -= dq;
                qc_[c] += dq;
                theta_[c] = float(r.theta);
                cd += dq;
                wa += double(qv_[c]) + qc_[c];
                dr = std::max(dr, std::fabs(theta_[c] - lk * qc_[c] - thl0));
            }
            before[size_t(k)] = wb, after[size_t(k)] = wa, drift[size_t(k)] = dr, cond[size_t(k)] = cd;
        });
        double wb = 0, wa = 0;
        for (int k = 0; k < nz; ++k) {
            wb += before[size_t(k)], wa += after[size_t(k)];
            rep.theta_l_drift = std::max(rep.theta_l_drift, drift[size_t(k)]);
            rep.condensed += cond[size_t(k)];
        }
        rep.water_drift = std::max(rep.water_drift, wb > 0 ? std::fabs(wa - wb) / wb : 0.0);
    }
    rep.seconds_thermo += seconds_since(t0);
    // Kessler warm rain: conversions, evaporation, fallout.
    if (!qr_.empty()) {
        t0 = Clock::now();
        KesslerReport kr = kessler_conversions(spec_, theta_, qv_, qc_, qr_, ref_.pressure, ref_.exner, ref_.rho, dt, opt_.kessler);
        rep.autoconverted += kr.autoconverted;
        rep.accreted += kr.accreted;
        rep.rain_evaporated += kr.evaporated;
        if (opt_.kessler.sedimentation) {
            KesslerReport sr = rain_sedimentation(spec_, qr_, ref_.rho, dt, opt_.kessler);
            rep.rain_fallout += sr.fallout;
            rep.sedimentation_substeps += sr.sedimentation_substeps;
        }
        rep.seconds_rain += seconds_since(t0);
    }
}

namespace {
template <class F>
void for_components(MacVelocity& a, F&& f) {
    f(a.u, 0);
    f(a.v, 1);
    f(a.w, 2);
}
Lattice component_lattice(const GridSpec& g, int c) { return c == 0 ? u_lattice(g) : c == 1 ? v_lattice(g) : w_lattice(g); }
bool component_moves(const GridSpec& g, int c) { return (c == 0 ? g.nx : c == 1 ? g.ny : g.nz) > 1; }
} // namespace

// Advects theta, qv, qc (and qr) by `vel` over dt on the cell lattice. Reversible
// mode: theta_e (conserved by reversible moist adiabatic motion) is what gets
// advected; theta is recovered afterwards at the new level.
void Simulation::advect_scalars(const MacVelocity& vel, const Lattice& cl, double dt) {
    const int nz = spec_.nz;
    const size_t plane = size_t(spec_.nx) * spec_.ny;
    if (opt_.reversible_theta_e && opt_.moist) {
        parallel_for_index(nz, [&](int k) {
            const double pi = ref_.exner[size_t(k)], p = ref_.pressure[size_t(k)];
            for (size_t c = size_t(k) * plane; c < size_t(k + 1) * plane; ++c)
                theta_[c] = float(equivalent_potential_temperature(theta_[c] * pi, p, qv_[c], double(qv_[c]) + qc_[c]));
        });
    }
    {
        std::vector<float>&a = scalar_tmp_[0], &b = scalar_tmp_[1], &c = scalar_tmp_[2];
        a.resize(theta_.size());
        b.resize(theta_.size());
        c.resize(qr_.size());
        std::span<const float> in[4] = {theta_, qv_, qc_, qr_};
        std::span<float> out[4] = {tmp_, a, b, c};
        advect_many(vel, cl, std::span(in, qr_.empty() ? 3 : 4), std::span(out, qr_.empty() ? 3 : 4), dt, opt_.scheme,
                    *scratch_);
        theta_.swap(tmp_);
        qv_.swap(a);
        qc_.swap(b);
        qr_.swap(c);
    }
    if (opt_.reversible_theta_e && opt_.moist) {
        parallel_for_index(nz, [&](int k) {
            const double pi = ref_.exner[size_t(k)], p = ref_.pressure[size_t(k)];
            for (size_t c = size_t(k) * plane; c < size_t(k + 1) * plane; ++c)
                theta_[c] = float(temperature_from_theta_e(theta_[c], p, qv_[c], double(qv_[c]) + qc_[c]) / pi);
        });
    }
}

void Simulation::substep_trapezoidal(double dt, StepReport& rep) {
    const int nz = spec_.nz;
    const size_t plane = size_t(spec_.nx) * spec_.ny;
    const double h2 = spec_.dx * spec_.dx;
    auto t0 = Clock::now();
    // 0. Departure-point half of the forces, from the state at t^n. Velocity:
    //    S = u^n - (dt / dt_prev) g + dt/2 b^n + dt/2 nu lap u^n, with g the last
    //    projection's removed part (dt_prev/2 grad p^n). Trace velocity (into
    //    vel_prev_): u^n + (dt / (2 dt_prev)) (u^n - u^{n-1}).
    const bool history = history_dt_ > 0;
    const double r = history ? dt / history_dt_ : 0.0;
    if (!history) {
        vel_prev_ = vel_;
        grad_ = vel_;
    } else {
        for_components(grad_, [&](std::vector<float>& g, int c) {
            const std::vector<float>& u = c == 0 ? vel_.u : c == 1 ? vel_.v : vel_.w;
            std::vector<float>& up = c == 0 ? vel_prev_.u : c == 1 ? vel_prev_.v : vel_prev_.w;
            for (size_t n = 0; n < g.size(); ++n) {
                g[n] = float(u[n] - r * g[n]);
                up[n] = float(u[n] + 0.5 * r * (double(u[n]) - up[n]));
            }
        });
    }
    buoyancy_into(grad_, 0.5 * dt);
    if (opt_.viscosity > 0)
        for_components(grad_, [&](std::vector<float>& g, int c) {
            if (component_moves(spec_, c))
                lap_accumulate(component_lattice(spec_, c), c == 0 ? vel_.u : c == 1 ? vel_.v : vel_.w, g,
                               0.5 * dt * opt_.viscosity / h2, nullptr);
        });
    grad_.enforce_walls();
    add_sources(0.5 * dt, rep);
    if (opt_.diffusivity > 0) {
        const Lattice l = cell_lattice(spec_);
        const double c = 0.5 * dt * opt_.diffusivity / h2;
        diffuse_lattice(l, theta_, c, &ref_.theta);
        diffuse_lattice(l, qv_, c, &ref_.qv);
        diffuse_lattice(l, qc_, c, nullptr);
        rep.water_redistributed += redistribute_negatives(qv_, nz, plane) + redistribute_negatives(qc_, nz, plane);
    }
    rep.seconds_forces += seconds_since(t0);
    // 1. Advection along the time-centred trajectory.
    t0 = Clock::now();
    const Lattice cl = cell_lattice(spec_);
    advect_scalars(vel_prev_, cl, dt);
    for_components(grad_, [&](std::vector<float>& g, int c) {
        if (!component_moves(spec_, c)) return;
        std::span<const float> qs[1] = {g};
        std::span<float> os[1] = {c == 0 ? vel_tmp_.u : c == 1 ? vel_tmp_.v : vel_tmp_.w};
        advect_many(vel_prev_, component_lattice(spec_, c), qs, os, dt, opt_.scheme, *scratch_);
    });
    vel_tmp_.enforce_walls();
    std::swap(vel_prev_, vel_); // vel_prev_ = u^n, vel_ = trace velocity
    std::swap(vel_, vel_tmp_);  // vel_ = advected, vel_tmp_ = trace velocity
    rep.seconds_advect += seconds_since(t0);
    // 2. Arrival half of the sources and of the scalar diffusion, thermodynamics.
    t0 = Clock::now();
    add_sources(0.5 * dt, rep);
    rep.seconds_sources += seconds_since(t0);
    if (opt_.diffusivity > 0) {
        t0 = Clock::now();
        const double c = 0.5 * dt * opt_.diffusivity / h2;
        diffuse_heun(cl, theta_, c, &ref_.theta, scalar_tmp_[0]);
        diffuse_heun(cl, qv_, c, &ref_.qv, scalar_tmp_[0]);
        diffuse_heun(cl, qc_, c, nullptr, scalar_tmp_[0]);
        rep.water_redistributed += redistribute_negatives(qv_, nz, plane) + redistribute_negatives(qc_, nz, plane);
        rep.seconds_forces += seconds_since(t0);
    }
    thermodynamics(dt, rep);
    // 3. Arrival half of buoyancy and viscosity; confinement (O(dx), first order).
    t0 = Clock::now();
    buoyancy(0.5 * dt);
    if (opt_.viscosity > 0) {
        std::vector<float> s;
        for_components(vel_, [&](std::vector<float>& q, int c) {
            if (component_moves(spec_, c)) diffuse_heun(component_lattice(spec_, c), q, 0.5 * dt * opt_.viscosity / h2, nullptr, s);
        });
        vel_.enforce_walls();
    }
    if (opt_.vorticity_confinement > 0) confinement(dt);
    rep.seconds_forces += seconds_since(t0);
    // 4. Projection; its removed part g = u* - u^{n+1} = dt/2 grad p^{n+1} is kept.
    t0 = Clock::now();
    grad_ = vel_;
    ProjectionReport pr = solver_.project(vel_, opt_.projection);
    for_components(grad_, [&](std::vector<float>& g, int c) {
        const std::vector<float>& u = c == 0 ? vel_.u : c == 1 ? vel_.v : vel_.w;
        for (size_t n = 0; n < g.size(); ++n) g[n] -= u[n];
    });
    rep.pressure_iterations += pr.iterations;
    rep.max_pressure_iterations = std::max(rep.max_pressure_iterations, pr.iterations);
    rep.pressure_converged = rep.pressure_converged && pr.converged;
    rep.divergence = pr.after;
    rep.seconds_project += seconds_since(t0);
    // 5. Embedded error estimate: the trace velocity against the time-centred
    //    mean of the velocities now known, as a displacement in cells.
    double err = 0;
    for_components(vel_tmp_, [&](std::vector<float>& t, int c) {
        const std::vector<float>& a = c == 0 ? vel_prev_.u : c == 1 ? vel_prev_.v : vel_prev_.w;
        const std::vector<float>& b = c == 0 ? vel_.u : c == 1 ? vel_.v : vel_.w;
        for (size_t n = 0; n < t.size(); ++n) err = std::max(err, std::fabs(double(t[n]) - 0.5 * (double(a[n]) + b[n])));
    });
    err *= dt / spec_.dx;
    rep.step_error = std::max(rep.step_error, err);
    last_error_ = err;
    last_dt_ = dt;
    history_dt_ = dt;
}

void Simulation::substep(double dt, StepReport& rep) {
    if (!opt_.advection_reflection && opt_.time_scheme == TimeScheme::Trapezoidal) {
        substep_trapezoidal(dt, rep);
        return;
    }
    const int nx = spec_.nx, ny = spec_.ny, nz = spec_.nz;
    const size_t plane = size_t(nx) * ny;
    auto t0 = Clock::now();
    // 1. Advection of scalars by the old velocity, then of the velocity itself.
    Lattice cl = cell_lattice(spec_);
    const bool reflect = opt_.advection_reflection;
    if (reflect) {
        // Advection-reflection (Zehnder, Narain & Thomaszewski 2018): half a step
        // of advection and buoyancy, projected to u_half; the projection's
        // removed part is reflected (2 u_half - u~) and advected by u_half for the
        // second half, which keeps the kinetic energy the plain split loses.
        advect_velocity(vel_, vel_tmp_, 0.5 * dt, opt_.scheme, *scratch_);
        std::swap(vel_, vel_tmp_);
        buoyancy(0.5 * dt);
        vel_tmp_ = vel_; // u~ before the projection
        ProjectionReport pr = solver_.project(vel_, opt_.projection);
        rep.pressure_iterations += pr.iterations;
        rep.max_pressure_iterations = std::max(rep.max_pressure_iterations, pr.iterations);
        rep.pressure_converged = rep.pressure_converged && pr.converged;
        auto refl = [](std::vector<float>& r, const std::vector<float>& half) {
            for (size_t n = 0; n < r.size(); ++n) r[n] = 2 * half[n] - r[n];
        };
        refl(vel_tmp_.u, vel_.u);
        refl(vel_tmp_.v, vel_.v);
        refl(vel_tmp_.w, vel_.w);
    }
    advect_scalars(vel_, cl, dt);
    if (!reflect) {
        advect_velocity(vel_, vel_tmp_, dt, opt_.scheme, *scratch_);
        std::swap(vel_, vel_tmp_);
    } else {
        // Second half: the reflected field (vel_tmp_) advected by u_half (vel_).
        const GridSpec& g = spec_;
        auto one = [&](const Lattice& l, const std::vector<float>& q, std::vector<float>& o) {
            std::span<const float> qs[1] = {q};
            std::span<float> os[1] = {o};
            advect_many(vel_, l, qs, os, 0.5 * dt, opt_.scheme, *scratch_);
        };
        if (g.nx > 1) one(u_lattice(g), vel_tmp_.u, vel_third_.u);
        if (g.ny > 1) one(v_lattice(g), vel_tmp_.v, vel_third_.v);
        if (g.nz > 1) one(w_lattice(g), vel_tmp_.w, vel_third_.w);
        vel_third_.enforce_walls();
        std::swap(vel_, vel_third_);
    }
    rep.seconds_advect += seconds_since(t0);
    // 2. Sources.
    t0 = Clock::now();
    add_sources(dt, rep);
    rep.seconds_sources += seconds_since(t0);
    // 3. Saturation adjustment, Kessler rain.
    thermodynamics(dt, rep);
    // 4. Forces.
    t0 = Clock::now();
    buoyancy(reflect ? 0.5 * dt : dt);
    if (opt_.vorticity_confinement > 0) confinement(dt);
    if (opt_.viscosity > 0 || opt_.diffusivity > 0) {
        diffuse(dt);
        rep.water_redistributed += redistribute_negatives(qv_, nz, plane) + redistribute_negatives(qc_, nz, plane);
    }
    rep.seconds_forces += seconds_since(t0);
    // 5. Projection.
    t0 = Clock::now();
    ProjectionReport pr = solver_.project(vel_, opt_.projection);
    rep.pressure_iterations += pr.iterations;
    rep.max_pressure_iterations = std::max(rep.max_pressure_iterations, pr.iterations);
    rep.pressure_converged = rep.pressure_converged && pr.converged;
    rep.divergence = pr.after;
    rep.seconds_project += seconds_since(t0);
}

StepReport Simulation::step(double dt) {
    if (!std::isfinite(dt) || dt <= 0) throw Error("sim step: dt must be finite and > 0 s");
    check_finite(theta_, "theta");
    check_finite(qv_, "qv");
    check_finite(qc_, "qc");
    check_finite(qr_, "qr");
    check_nonnegative(qv_, "qv");
    check_nonnegative(qc_, "qc");
    check_nonnegative(qr_, "qr");
    if (!std::isfinite(vel_.max_abs())) throw Error("sim step: velocity holds NaN/Inf");
    StepReport rep;
    const double h = spec_.dx;
    const bool controlled = !opt_.advection_reflection && opt_.time_scheme == TimeScheme::Trapezoidal &&
                            opt_.step_error_tolerance > 0;
    const char* why = "step";
    auto limit = [&]() {
        double lim = 1e30;
        why = "step";
        auto take = [&](double l, const char* w) {
            if (l < lim) lim = l, why = w;
        };
        double vmax = vel_.max_abs();
        if (vmax > 0) take(opt_.cfl * h / vmax, "cfl");
        double b = max_buoyancy();
        if (b > 0) take(opt_.cfl * std::sqrt(h / b), "buoyancy"); // distance from rest under b stays < cfl cells
        double nu = std::max(opt_.viscosity, opt_.diffusivity);
        if (nu > 0) take(h * h / (8 * nu), "diffusion");
        rep.accuracy_dt = 0;
        if (controlled && !(history_dt_ > 0) && b > 0) {
            // Start-up substep (no history, so no estimate yet): from rest the
            // estimate is |du| dt / (2 dx) ~ b dt^2 / (2 dx); keep it within the tolerance.
            rep.accuracy_dt = std::sqrt(2 * opt_.step_error_tolerance * h / b);
            take(rep.accuracy_dt, "accuracy");
        } else if (controlled && history_dt_ > 0 && last_dt_ > 0) {
            // err ~ dt^3: the substep that would make it 0.9^3 of the tolerance, grown at most 2x.
            const double acc = last_error_ > 0 ? std::min(2 * last_dt_, 0.9 * last_dt_ * std::cbrt(opt_.step_error_tolerance / last_error_))
                                               : 2 * last_dt_;
            rep.accuracy_dt = acc;
            take(acc, "accuracy");
        }
        return lim;
    };
    double remaining = dt;
    double first = limit();
    double need = std::ceil(dt / first - 1e-9);
    if (need > opt_.max_substeps) {
        char buf[300];
        std::snprintf(buf, sizeof buf,
                      "sim step: dt = %g s needs %.0f substeps at CFL %g (limited by %s; max_substeps = %d); lower dt "
                      "or raise options.max_substeps",
                      dt, need, opt_.cfl, why, opt_.max_substeps);
        throw Error(buf);
    }
    while (remaining > 1e-12 * dt) {
        if (rep.substeps >= opt_.max_substeps)
            throw Error("sim step: the flow accelerated past max_substeps = " + std::to_string(opt_.max_substeps) +
                        " within one step (time reached " + std::to_string(time_) + " s)");
        double lim = limit();
        int n = int(std::ceil(remaining / lim - 1e-9));
        double sdt = n <= 1 ? remaining : remaining / n;
        if (n > 1 || rep.substeps == 0) rep.dt_limit = n > 1 ? why : "step"; // what split the step
        substep(sdt, rep);
        rep.substep_dt = sdt;
        remaining -= sdt;
        time_ += sdt;
        ++rep.substeps;
    }
    rep.dt = dt;
    // Summary statistics (fixed order).
    double tw = 0;
    const double cell_volume = h * h * h;
    rep.max_theta_perturbation = -1e30, rep.min_theta_perturbation = 1e30;
    for (int k = 0; k < spec_.nz; ++k) {
        size_t plane = size_t(spec_.nx) * spec_.ny;
        double row = 0;
        for (size_t c = size_t(k) * plane; c < size_t(k + 1) * plane; ++c) {
            double q = double(qv_[c]) + qc_[c];
            if (!qr_.empty()) {
                q += qr_[c];
                rep.max_qr = std::max(rep.max_qr, double(qr_[c]));
            }
            row += q;
            double tp = theta_[c] - ref_.theta[size_t(k)];
            rep.max_theta_perturbation = std::max(rep.max_theta_perturbation, tp);
            rep.min_theta_perturbation = std::min(rep.min_theta_perturbation, tp);
            rep.max_qc = std::max(rep.max_qc, double(qc_[c]));
        }
        tw += row;
        rep.water_mass += row * ref_.rho[size_t(k)] * cell_volume;
    }
    rep.total_water = tw;
    for (float w : vel_.w) rep.max_w = std::max(rep.max_w, double(w));
    rep.max_speed = vel_.max_abs();
    return rep;
}

namespace {
Box3d grid_box(const GridSpec& s) {
    Box3d b;
    b.max = Vec3d{{s.nx * s.dx, s.ny * s.dx, s.nz * s.dx}};
    return b;
}
} // namespace

Field3D Simulation::cloud_water() const {
    Field3D f(Vec3i{{spec_.nx, spec_.ny, spec_.nz}}, 1, grid_box(spec_), {"qc"});
    std::copy(qc_.begin(), qc_.end(), f.channel(0).begin());
    return f;
}

Field3D Simulation::vapour() const {
    Field3D f(Vec3i{{spec_.nx, spec_.ny, spec_.nz}}, 1, grid_box(spec_), {"qv"});
    std::copy(qv_.begin(), qv_.end(), f.channel(0).begin());
    return f;
}

Field3D Simulation::rain_water() const {
    Field3D f(Vec3i{{spec_.nx, spec_.ny, spec_.nz}}, 1, grid_box(spec_), {"qr"});
    if (!qr_.empty()) std::copy(qr_.begin(), qr_.end(), f.channel(0).begin());
    return f;
}

Field3D Simulation::temperature() const {
    Field3D f(Vec3i{{spec_.nx, spec_.ny, spec_.nz}}, 1, grid_box(spec_), {"T"});
    auto out = f.channel(0);
    size_t plane = size_t(spec_.nx) * spec_.ny;
    for (size_t c = 0; c < theta_.size(); ++c) out[c] = float(theta_[c] * ref_.exner[c / plane]);
    return f;
}

Field3D Simulation::theta_perturbation() const {
    Field3D f(Vec3i{{spec_.nx, spec_.ny, spec_.nz}}, 1, grid_box(spec_), {"theta_p"});
    auto out = f.channel(0);
    size_t plane = size_t(spec_.nx) * spec_.ny;
    for (size_t c = 0; c < theta_.size(); ++c) out[c] = float(theta_[c] - ref_.theta[c / plane]);
    return f;
}

Field3D Simulation::velocity_field() const {
    Field3D f(Vec3i{{spec_.nx, spec_.ny, spec_.nz}}, 3, grid_box(spec_), {"u", "v", "w"});
    for (int k = 0; k < spec_.nz; ++k)
        for (int j = 0; j < spec_.ny; ++j)
            for (int i = 0; i < spec_.nx; ++i) {
                f.at(0, i, j, k) = 0.5f * (vel_.u[vel_.iu(i, j, k)] + vel_.u[vel_.iu(i + 1, j, k)]);
                f.at(1, i, j, k) = 0.5f * (vel_.v[vel_.iv(i, j, k)] + vel_.v[vel_.iv(i, j + 1, k)]);
                f.at(2, i, j, k) = 0.5f * (vel_.w[vel_.iw(i, j, k)] + vel_.w[vel_.iw(i, j, k + 1)]);
            }
    return f;
}

} // namespace atlas::sim

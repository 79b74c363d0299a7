// Convergence study of the cloud solver (docs/solver.md "Convergence order"):
// problems with a known answer, solved at doubling resolutions at a fixed CFL
// number, the error in the L2 (RMS) and max norms and the observed order
// p = log2(E(2h) / E(h)) between successive resolutions, printed as Markdown.
// Not a timing benchmark: each case runs once (Iterations(1)).
//
//  Rotation:    a smooth Gaussian blob (sigma = L/12, centred L/4 off the axis)
//               advected by a prescribed solid-body rotation for one full turn
//               in a closed 2D slab; exact answer: the initial blob. Only the
//               advection scheme (advect()) is exercised.
//  TaylorGreen: u = U sin(kx) cos(kz), w = -U cos(kx) sin(kz), k = pi/L, in a
//               closed free-slip L x L slab through the whole Simulation (dry,
//               Boussinesq, neutral, no buoyancy): advection, projection, time
//               splitting and the explicit viscosity. Exact answer: the initial
//               field times exp(-2 nu k^2 t) (steady when nu = 0).
//  PeriodicTaylorGreen: the doubly periodic vortex u = U sin(kx) cos(ky),
//               v = -U cos(kx) sin(ky), k = 2 pi / L, L = 2 km (four 1 km vortex
//               cells, so n cells here have the dx of n/2 in the closed case), in
//               an x-y plane one cell thick, periodic x and y: no walls at all.
//  PeriodicTranslation: a Gaussian blob (sigma = L/10) carried by a uniform
//               wind (U, U/2) twice round x and once round y of a doubly
//               periodic square (advect() alone), and once across an x-z slab
//               (periodic x, closed floor and lid) through the whole Simulation;
//               exact answer: the initial blob.
//  Thermal:     a dry 2 K cos^2 warm bubble (radius 400 m, 500 m up) in a
//               neutral 300 K slab, anelastic, 2 km x 2 km, 120 s; answer: the
//               finest run (theta' at cell centres box-averaged onto each
//               coarser grid).
//  BryanFritsch: their dry case (20 x 10 km, 2 K, radius 2 km, 2 km up, 1000 s)
//               at 400/200/100 m against the 50 m run, the same way.
//
// Run:   build/bench/sim_convergence_bench --benchmark_filter=Convergence
//        (ConvergenceRotation, ConvergenceTaylorGreen[Viscous],
//         ConvergencePeriodicTaylorGreen[Viscous], ConvergencePeriodicTranslation,
//         ConvergenceThermal; Smoke for CI, < 1 s)
//        build/bench/sim_convergence_bench --benchmark_filter=DensityCurrent_200
//        (Straka et al. 1993 density current: peak w against CFL and the step
//         tolerance, both time schemes; DensityCurrent_100 at the published 100 m)
#include "atlas/sim/simulation.h"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

using namespace atlas::sim;

namespace {

struct Norms {
    double l2 = 0, max = 0;
};

void add(Norms& e, double d, double& sum2, size_t& count) {
    sum2 += d * d;
    ++count;
    e.max = std::max(e.max, std::fabs(d));
}

const char* scheme_name(AdvectionScheme s) {
    return s == AdvectionScheme::SemiLagrangian ? "semi-Lagrangian" : s == AdvectionScheme::MacCormack ? "MacCormack (limited)" : "limited cubic";
}

const char* time_name(TimeScheme t) { return t == TimeScheme::Split ? "split (1st order)" : "trapezoidal (2nd order)"; }

void print_rows(const std::string& label, const std::vector<int>& ns, const std::vector<Norms>& e) {
    for (size_t r = 0; r < ns.size(); ++r) {
        std::printf("| %s | %d | %.3e | %.3e |", label.c_str(), ns[r], e[r].l2, e[r].max);
        if (r == 0) std::printf(" | |\n");
        else std::printf(" %.2f | %.2f |\n", std::log2(e[r - 1].l2 / e[r].l2), std::log2(e[r - 1].max / e[r].max));
    }
    std::fflush(stdout);
}

void print_header(const char* title) {
    std::printf("\n%s\n\n| scheme | n | L2 error | max error | L2 order | max order |\n|---|---|---|---|---|---|\n", title);
}

// ---- Rotation -------------------------------------------------------------

Norms rotation(int n, AdvectionScheme scheme, double cfl) {
    const double L = 1000, omega = 2 * M_PI / 1000; // one turn in 1000 s
    GridSpec s;
    s.nx = n, s.ny = 1, s.nz = n, s.dx = L / n;
    MacVelocity vel(s);
    const double c = L / 2;
    for (int k = 0; k < n; ++k)
        for (int i = 0; i <= n; ++i) vel.u[vel.iu(i, 0, k)] = float(-omega * ((k + 0.5) * s.dx - c));
    for (int k = 0; k <= n; ++k)
        for (int i = 0; i < n; ++i) vel.w[vel.iw(i, 0, k)] = float(omega * ((i + 0.5) * s.dx - c));
    vel.enforce_walls();
    const Lattice l = cell_lattice(s);
    std::vector<float> q(l.size()), out(l.size()), q0(l.size());
    const double sigma = L / 12, bx = c + L / 4, bz = c;
    for (int k = 0; k < n; ++k)
        for (int i = 0; i < n; ++i) {
            const double x = (i + 0.5) * s.dx - bx, z = (k + 0.5) * s.dx - bz;
            q0[size_t(k) * n + i] = float(std::exp(-(x * x + z * z) / (sigma * sigma)));
        }
    q = q0;
    // Speed at the blob's outer edge (r = L/2): cfl cells per step there.
    const double vmax = omega * L / 2;
    const int steps = int(std::ceil(1000 / (cfl * s.dx / vmax)));
    const double dt = 1000.0 / steps;
    for (int st = 0; st < steps; ++st) {
        advect(vel, l, q, out, dt, scheme);
        q.swap(out);
    }
    Norms e;
    double sum2 = 0;
    size_t cnt = 0;
    for (size_t m = 0; m < q.size(); ++m) add(e, double(q[m]) - q0[m], sum2, cnt);
    e.l2 = std::sqrt(sum2 / double(cnt));
    return e;
}

void rotation_study(benchmark::State& state, std::vector<int> ns, double cfl) {
    for (auto _ : state) {
        char title[160];
        std::snprintf(title, sizeof title, "Rotation: Gaussian blob, one turn, CFL %.2g at r = L/2 (advect() only)", cfl);
        print_header(title);
        for (AdvectionScheme sc : {AdvectionScheme::SemiLagrangian, AdvectionScheme::MacCormack, AdvectionScheme::CubicLimited}) {
            std::vector<Norms> e;
            for (int n : ns) e.push_back(rotation(n, sc, cfl));
            print_rows(scheme_name(sc), ns, e);
        }
    }
}

// ---- Taylor-Green -----------------------------------------------------------

Norms taylor_green(int n, AdvectionScheme scheme, TimeScheme ts, double cfl, double nu, double T) {
    const double L = 1000, U = 10, k = M_PI / L;
    GridSpec s;
    s.nx = n, s.ny = 1, s.nz = n, s.dx = L / n;
    Sounding snd; // neutral 300 K, dry: no buoyancy
    SimOptions o;
    o.anelastic = false;
    o.moist = false;
    o.scheme = scheme;
    o.time_scheme = ts;
    o.cfl = cfl;
    o.viscosity = nu;
    o.max_substeps = 10000;
    o.step_error_tolerance = 0; // CFL-limited only: the order at a fixed CFL
    o.projection.tolerance = 1e-10;
    o.projection.max_iterations = 1000;
    Simulation sim(s, snd, o);
    MacVelocity& v = sim.velocity();
    auto uex = [&](double x, double z, double a) { return a * U * std::sin(k * x) * std::cos(k * z); };
    for (int kk = 0; kk < n; ++kk)
        for (int i = 0; i <= n; ++i) v.u[v.iu(i, 0, kk)] = float(uex(i * s.dx, (kk + 0.5) * s.dx, 1));
    for (int kk = 0; kk <= n; ++kk)
        for (int i = 0; i < n; ++i) v.w[v.iw(i, 0, kk)] = float(-uex((kk)*s.dx, (i + 0.5) * s.dx, 1)); // -U cos(kx) sin(kz) by symmetry
    v.enforce_walls();
    sim.step(T);
    const double a = std::exp(-2 * nu * k * k * T);
    Norms e;
    double sum2 = 0;
    size_t cnt = 0;
    for (int kk = 0; kk < n; ++kk)
        for (int i = 0; i <= n; ++i) add(e, v.u[v.iu(i, 0, kk)] - uex(i * s.dx, (kk + 0.5) * s.dx, a), sum2, cnt);
    for (int kk = 0; kk <= n; ++kk)
        for (int i = 0; i < n; ++i) add(e, v.w[v.iw(i, 0, kk)] + uex(kk * s.dx, (i + 0.5) * s.dx, a), sum2, cnt);
    e.l2 = std::sqrt(sum2 / double(cnt));
    return e;
}

void taylor_green_study(benchmark::State& state, std::vector<int> ns, double cfl, double nu, double T) {
    for (auto _ : state) {
        char title[200];
        std::snprintf(title, sizeof title,
                      "Taylor-Green vortex: U = 10 m/s, L = 1 km, nu = %g m^2/s, t = %g s, CFL %.2g (velocity error, m/s)", nu, T, cfl);
        print_header(title);
        for (TimeScheme ts : {TimeScheme::Split, TimeScheme::Trapezoidal})
            for (AdvectionScheme sc : {AdvectionScheme::SemiLagrangian, AdvectionScheme::MacCormack, AdvectionScheme::CubicLimited}) {
                std::vector<Norms> e;
                for (int n : ns) e.push_back(taylor_green(n, sc, ts, cfl, nu, T));
                print_rows(std::string(scheme_name(sc)) + ", " + time_name(ts), ns, e);
            }
    }
}

// ---- Periodic Taylor-Green and translation ------------------------------------

GridSpec periodic_grid(int nx, int ny, int nz, double dx) {
    GridSpec s;
    s.nx = nx, s.ny = ny, s.nz = nz, s.dx = dx;
    s.boundary = {Boundary::Periodic, Boundary::Periodic, Boundary::Periodic, Boundary::Periodic, Boundary::Closed, Boundary::Closed};
    return s;
}

Norms periodic_taylor_green(int n, AdvectionScheme scheme, TimeScheme ts, double cfl, double nu, double T) {
    const double L = 2000, U = 10, k = 2 * M_PI / L;
    const GridSpec s = periodic_grid(n, n, 1, L / n);
    SimOptions o;
    o.anelastic = false;
    o.moist = false;
    o.scheme = scheme;
    o.time_scheme = ts;
    o.cfl = cfl;
    o.viscosity = nu;
    o.max_substeps = 10000;
    o.step_error_tolerance = 0;
    o.projection.tolerance = 1e-10;
    o.projection.max_iterations = 1000;
    Simulation sim(s, Sounding{}, o);
    MacVelocity& v = sim.velocity();
    auto fu = [&](double x, double y, double a) { return a * U * std::sin(k * x) * std::cos(k * y); };
    auto fv = [&](double x, double y, double a) { return -a * U * std::cos(k * x) * std::sin(k * y); };
    for (int j = 0; j < n; ++j)
        for (int i = 0; i <= n; ++i) v.u[v.iu(i, j, 0)] = float(fu(i * s.dx, (j + 0.5) * s.dx, 1));
    for (int j = 0; j <= n; ++j)
        for (int i = 0; i < n; ++i) v.v[v.iv(i, j, 0)] = float(fv((i + 0.5) * s.dx, j * s.dx, 1));
    sim.step(T);
    const double a = std::exp(-2 * nu * k * k * T);
    Norms e;
    double sum2 = 0;
    size_t cnt = 0;
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) { // faces 0..n-1 (face n is face 0)
            add(e, v.u[v.iu(i, j, 0)] - fu(i * s.dx, (j + 0.5) * s.dx, a), sum2, cnt);
            add(e, v.v[v.iv(i, j, 0)] - fv((i + 0.5) * s.dx, j * s.dx, a), sum2, cnt);
        }
    e.l2 = std::sqrt(sum2 / double(cnt));
    return e;
}

void periodic_taylor_green_study(benchmark::State& state, std::vector<int> ns, double cfl, double nu, double T) {
    for (auto _ : state) {
        char title[240];
        std::snprintf(title, sizeof title,
                      "Doubly periodic Taylor-Green vortex: U = 10 m/s, L = 2 km (1 km vortices), nu = %g m^2/s, t = %g s, CFL %.2g "
                      "(velocity error, m/s)",
                      nu, T, cfl);
        print_header(title);
        for (TimeScheme ts : {TimeScheme::Split, TimeScheme::Trapezoidal})
            for (AdvectionScheme sc : {AdvectionScheme::SemiLagrangian, AdvectionScheme::MacCormack, AdvectionScheme::CubicLimited}) {
                std::vector<Norms> e;
                for (int n : ns) e.push_back(periodic_taylor_green(n, sc, ts, cfl, nu, T));
                print_rows(std::string(scheme_name(sc)) + ", " + time_name(ts), ns, e);
            }
    }
}

std::vector<float> gaussian(int nx, int ny, double dx, double cx, double cy, double sigma, double amp) {
    std::vector<float> q(size_t(nx) * ny);
    for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i) {
            const double x = (i + 0.5) * dx - cx, y = (j + 0.5) * dx - cy;
            q[size_t(j) * nx + i] = float(amp * std::exp(-(x * x + y * y) / (2 * sigma * sigma)));
        }
    return q;
}

Norms compare(const std::vector<float>& a, const std::vector<float>& b, double scale) {
    Norms e;
    double sum2 = 0;
    size_t cnt = 0;
    for (size_t m = 0; m < a.size(); ++m) add(e, (double(a[m]) - b[m]) / scale, sum2, cnt);
    e.l2 = std::sqrt(sum2 / double(cnt));
    return e;
}

// advect() alone: twice round x, once round y of a doubly periodic square.
// peak_loss (optional): max(q0) - max(q), how much of the peak the limiter clipped.
// diagonal = false: the wind is (U, 0), the blob crosses x only (its y samples stay put).
Norms periodic_translation(int n, AdvectionScheme scheme, double cfl, double* peak_loss = nullptr, bool diagonal = true) {
    const double L = 1000, U = 10, T = 2 * L / U;
    const GridSpec s = periodic_grid(n, n, 1, L / n);
    MacVelocity vel(s);
    std::fill(vel.u.begin(), vel.u.end(), float(U));
    std::fill(vel.v.begin(), vel.v.end(), float(diagonal ? U / 2 : 0.0));
    const Lattice l = cell_lattice(s);
    // Centred in the box: the Gaussian is 3.7e-6 at the seams (off centre it would
    // leave a jump across them that no scheme converges at second order).
    const std::vector<float> q0 = gaussian(n, n, s.dx, 0.5 * L, 0.5 * L, L / 10, 1);
    std::vector<float> q = q0, out(q0.size());
    const int steps = int(std::ceil(T / (cfl * s.dx / U)));
    for (int st = 0; st < steps; ++st) {
        advect(vel, l, q, out, T / steps, scheme);
        q.swap(out);
    }
    if (peak_loss) *peak_loss = double(*std::max_element(q0.begin(), q0.end())) - *std::max_element(q.begin(), q.end());
    return compare(q, q0, 1);
}

// The whole Simulation: an x-z slab (periodic x, closed floor and lid), dry,
// Boussinesq, a 10 m/s wind, a 1e-7 kg/kg vapour blob (so its buoyancy moves it
// by < 1e-4 cells) once across; error relative to the blob's amplitude.
Norms periodic_translation_sim(int n, AdvectionScheme scheme, TimeScheme ts, double cfl) {
    const double L = 1000, U = 10;
    const GridSpec s = periodic_grid(n, 1, n / 2, L / n);
    SimOptions o;
    o.moist = false;
    o.anelastic = false;
    o.scheme = scheme;
    o.time_scheme = ts;
    o.cfl = cfl;
    o.wind.assign(size_t(s.nz), U);
    o.step_error_tolerance = 0;
    o.max_substeps = 10000;
    Sounding snd;
    snd.surface_rh = snd.rh_above = snd.rh_lapse = 0;
    Simulation sim(s, snd, o);
    const std::vector<float> q0 = gaussian(n, n / 2, s.dx, 0.5 * L, 0.25 * L, L / 12, 1e-7); // 1e-6 of the peak at the x seam
    sim.qv() = q0;
    for (int st = 0; st < 10; ++st) sim.step(L / U / 10);
    return compare(sim.qv(), q0, 1e-7);
}

// Where the max-norm error of the periodic translation comes from: the peak the
// limiter clips (max(q0) - max(q)) against the max error.
void periodic_translation_peak(benchmark::State& state, std::vector<int> ns, double cfl, bool diagonal) {
    for (auto _ : state) {
        std::printf("\nPeriodic translation (advect() only, CFL %.2g, wind %s): max error and the peak lost, max(q0) - max(q)\n\n"
                    "| scheme | n | max error | peak lost |\n|---|---|---|---|\n",
                    cfl, diagonal ? "(U, U/2)" : "(U, 0)");
        for (AdvectionScheme sc : {AdvectionScheme::MacCormack, AdvectionScheme::CubicLimited})
            for (int n : ns) {
                double loss = 0;
                const Norms e = periodic_translation(n, sc, cfl, &loss, diagonal);
                std::printf("| %s | %d | %.3e | %.3e |\n", scheme_name(sc), n, e.max, loss);
                std::fflush(stdout);
            }
    }
}

void periodic_translation_study(benchmark::State& state, std::vector<int> ns, double cfl) {
    for (auto _ : state) {
        char title[240];
        std::snprintf(title, sizeof title,
                      "Periodic translation: Gaussian blob (sigma = L/10), uniform wind (U, U/2), twice round x and once round y, "
                      "CFL %.2g (advect() only; error relative to the peak)",
                      cfl);
        print_header(title);
        for (AdvectionScheme sc : {AdvectionScheme::SemiLagrangian, AdvectionScheme::MacCormack, AdvectionScheme::CubicLimited}) {
            std::vector<Norms> e;
            for (int n : ns) e.push_back(periodic_translation(n, sc, cfl));
            print_rows(scheme_name(sc), ns, e);
        }
        std::snprintf(title, sizeof title,
                      "Periodic translation through the Simulation: x-z slab (periodic x, closed floor and lid), 10 m/s wind, one "
                      "crossing, CFL %.2g (vapour blob sigma = L/12; error relative to the peak)",
                      cfl);
        print_header(title);
        for (TimeScheme ts : {TimeScheme::Split, TimeScheme::Trapezoidal})
            for (AdvectionScheme sc : {AdvectionScheme::SemiLagrangian, AdvectionScheme::MacCormack, AdvectionScheme::CubicLimited}) {
                std::vector<Norms> e;
                for (int n : ns) e.push_back(periodic_translation_sim(n, sc, ts, cfl));
                print_rows(std::string(scheme_name(sc)) + ", " + time_name(ts), ns, e);
            }
    }
}

// ---- Thermal (self-convergence) -----------------------------------------------

// A dry cos^2 warm bubble in a neutral 300 K slab of Lx x Lz (nx = n Lx / Lz
// cells), anelastic; theta' at cell centres after `seconds`.
struct ThermalCase {
    double Lx, Lz, radius, zc, amp, seconds;
    double nu = 0; // explicit viscosity = diffusivity, m^2/s
};
const ThermalCase kSmallThermal{2000, 2000, 400, 500, 2, 120};
const ThermalCase kBryanFritsch{20000, 10000, 2000, 2000, 2, 1000}; // B&F (2002) dry, full width
// The same with nu = kappa = 25 m^2/s: a problem with a converged answer (the
// inviscid one grows grid-scale billows on the rotors at every resolution).
const ThermalCase kBryanFritschViscous{20000, 10000, 2000, 2000, 2, 1000, 25};

std::vector<float> thermal(int n, AdvectionScheme scheme, TimeScheme ts, double cfl, const ThermalCase& tc = kSmallThermal) {
    GridSpec s;
    s.nz = n, s.ny = 1, s.dx = tc.Lz / n, s.nx = int(std::lround(tc.Lx / s.dx));
    Sounding snd;
    SimOptions o;
    o.moist = false;
    o.scheme = scheme;
    o.time_scheme = ts;
    o.cfl = cfl;
    o.max_substeps = 10000;
    o.step_error_tolerance = 0;
    o.projection.tolerance = 1e-10;
    o.projection.max_iterations = 1000;
    o.viscosity = o.diffusivity = tc.nu;
    Simulation sim(s, snd, o);
    std::vector<float> d(s.cells(), 0.f);
    for (int k = 0; k < s.nz; ++k)
        for (int i = 0; i < s.nx; ++i) {
            const double x = (i + 0.5) * s.dx - tc.Lx / 2, z = (k + 0.5) * s.dx - tc.zc;
            const double r = std::sqrt(x * x + z * z) / tc.radius;
            if (r < 1) d[size_t(k) * s.nx + i] = float(tc.amp * std::pow(std::cos(0.5 * M_PI * r), 2));
        }
    sim.add_theta(d);
    for (double t = 0; t < tc.seconds - 1e-9; t += 50) sim.step(std::min(50.0, tc.seconds - t));
    const atlas::Field3D tp = sim.theta_perturbation();
    return std::vector<float>(tp.channel(0).begin(), tp.channel(0).end());
}

// coarse (nxc x nzc) against the fine field box-averaged onto it.
Norms against(const std::vector<float>& coarse, int nc, const std::vector<float>& fine, int nf, double aspect = 1) {
    const int f = nf / nc, nxc = int(std::lround(nc * aspect)), nxf = int(std::lround(nf * aspect));
    Norms e;
    double sum2 = 0;
    size_t cnt = 0;
    for (int k = 0; k < nc; ++k)
        for (int i = 0; i < nxc; ++i) {
            double m = 0;
            for (int b = 0; b < f; ++b)
                for (int a = 0; a < f; ++a) m += fine[size_t(k * f + b) * nxf + size_t(i * f + a)];
            add(e, coarse[size_t(k) * nxc + i] - m / (f * f), sum2, cnt);
        }
    e.l2 = std::sqrt(sum2 / double(cnt));
    return e;
}

void thermal_study(benchmark::State& state, std::vector<int> ns, int nref, double cfl) {
    for (auto _ : state) {
        char title[200];
        std::snprintf(title, sizeof title,
                      "Dry thermal (2 K cos^2, 2 km slab, anelastic, 120 s), theta' (K) against the %d^2 run, CFL %.2g", nref, cfl);
        print_header(title);
        for (TimeScheme ts : {TimeScheme::Split, TimeScheme::Trapezoidal})
            for (AdvectionScheme sc : {AdvectionScheme::MacCormack}) {
                const std::vector<float> ref = thermal(nref, sc, ts, cfl);
                std::vector<Norms> e;
                for (int n : ns) e.push_back(against(thermal(n, sc, ts, cfl), n, ref, nref));
                print_rows(std::string(scheme_name(sc)) + ", " + time_name(ts), ns, e);
            }
    }
}


// ---- Density current (Straka et al. 1993): peak w against the CFL number ----

struct CurrentResult {
    double min_w = 0, max_w = 0, min_theta = 0, front = 0, seconds = 0, worst_error = 0;
    int substeps = 0;
};

// Half domain x in [0, 25.6 km] (x = 0 is the symmetry plane, a free-slip
// wall), z in [0, 6.4 km], neutral 300 K, T' = -7.5 (cos(pi l) + 1) K for
// l = |((x - 0) / 4 km, (z - 3 km) / 2 km)| <= 1 (theta' = T' / Pi0), nu = kappa
// = 75 m^2/s, 900 s. Peaks over the run sampled every 60 s.
CurrentResult density_current(double dx, TimeScheme ts, double cfl, double tol) {
    const int nx = int(std::lround(25600 / dx)), nz = int(std::lround(6400 / dx));
    GridSpec s;
    s.nx = nx, s.ny = 1, s.nz = nz, s.dx = dx;
    Sounding snd;
    SimOptions o;
    o.moist = false;
    o.time_scheme = ts;
    o.cfl = cfl;
    o.step_error_tolerance = tol;
    o.viscosity = o.diffusivity = 75;
    o.max_substeps = 10000;
    Simulation sim(s, snd, o);
    std::vector<float> d(s.cells(), 0.f);
    for (int k = 0; k < nz; ++k)
        for (int i = 0; i < nx; ++i) {
            const double x = (i + 0.5) * dx / 4000, z = ((k + 0.5) * dx - 3000) / 2000, l = std::sqrt(x * x + z * z);
            if (l <= 1) d[size_t(k) * nx + i] = float(-7.5 * (std::cos(M_PI * l) + 1) / sim.reference().exner[size_t(k)]);
        }
    sim.add_theta(d);
    CurrentResult r;
    const auto t0 = std::chrono::steady_clock::now();
    for (int st = 0; st < 15; ++st) {
        const StepReport rep = sim.step(60);
        r.substeps += rep.substeps;
        r.worst_error = std::max(r.worst_error, rep.step_error);
        for (float w : sim.velocity().w) r.min_w = std::min(r.min_w, double(w)), r.max_w = std::max(r.max_w, double(w));
        r.min_theta = rep.min_theta_perturbation; // at the end (900 s)
    }
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    // Front: the largest x of a surface cell with theta' < -1 K.
    const atlas::Field3D tp = sim.theta_perturbation();
    for (int i = 0; i < nx; ++i)
        if (tp.channel(0)[size_t(i)] < -1) r.front = (i + 0.5) * dx;
    return r;
}

void density_current_study(benchmark::State& state, double dx) {
    for (auto _ : state) {
        std::printf("\nDensity current (Straka 1993), dx = %g m, 900 s: peaks over the run (every 60 s)\n\n"
                    "| time scheme | CFL | step tolerance (cells) | substeps | worst step error (cells) | min w (m/s) | max w (m/s) | min theta' at 900 s (K) | front (m) | wall s |\n"
                    "|---|---|---|---|---|---|---|---|---|---|\n",
                    dx);
        struct Row {
            TimeScheme ts;
            double cfl, tol;
        };
        const Row rows[] = {{TimeScheme::Split, 2, 0},       {TimeScheme::Split, 1, 0},       {TimeScheme::Split, 0.5, 0},
                            {TimeScheme::Split, 0.25, 0},    {TimeScheme::Trapezoidal, 2, 0}, {TimeScheme::Trapezoidal, 1, 0},
                            {TimeScheme::Trapezoidal, 0.5, 0}, {TimeScheme::Trapezoidal, 0.25, 0},
                            {TimeScheme::Trapezoidal, 2, 0.02}, {TimeScheme::Trapezoidal, 2, 0.005},
                            {TimeScheme::Trapezoidal, 0.1, 0}};
        for (const Row& row : rows) {
            const CurrentResult r = density_current(dx, row.ts, row.cfl, row.tol);
            std::printf("| %s | %.2g | %g | %d | %.3g | %.2f | %.2f | %.2f | %.0f | %.1f |\n", time_name(row.ts), row.cfl, row.tol, r.substeps,
                        r.worst_error, r.min_w, r.max_w, r.min_theta, r.front, r.seconds);
            std::fflush(stdout);
        }
    }
}

void bryan_fritsch_study(benchmark::State& state, std::vector<int> ns, int nref, double cfl, bool split_too = true,
                         const ThermalCase* tcase = &kBryanFritsch) {
    const ThermalCase& tc = *tcase;
    for (auto _ : state) {
        char title[240];
        std::snprintf(title, sizeof title,
                      "Bryan & Fritsch (2002) dry thermal, 20 x 10 km, 1000 s, nu = kappa = %g m^2/s, theta' (K) against the %g m run, CFL %.2g "
                      "(rows: %g m down to %g m)",
                      tc.nu, 10000.0 / nref, cfl, 10000.0 / ns.front(), 10000.0 / ns.back());
        print_header(title);
        for (TimeScheme ts : {TimeScheme::Split, TimeScheme::Trapezoidal}) {
            if (ts == TimeScheme::Split && !split_too) continue;
            const std::vector<float> ref = thermal(nref, AdvectionScheme::MacCormack, ts, cfl, tc);
            std::vector<Norms> e;
            for (int n : ns) e.push_back(against(thermal(n, AdvectionScheme::MacCormack, ts, cfl, tc), n, ref, nref, 2.0));
            print_rows(std::string("MacCormack, ") + time_name(ts), ns, e);
        }
    }
}

} // namespace

BENCHMARK_CAPTURE(rotation_study, Smoke, std::vector<int>{16, 32}, 1.0)->Iterations(1)->Unit(benchmark::kSecond);
BENCHMARK_CAPTURE(taylor_green_study, Smoke, std::vector<int>{8, 16}, 1.0, 10.0, 20.0)->Iterations(1)->Unit(benchmark::kSecond);
BENCHMARK_CAPTURE(rotation_study, ConvergenceRotation, std::vector<int>{32, 64, 128, 256}, 1.0)->Iterations(1)->Unit(benchmark::kSecond);
BENCHMARK_CAPTURE(taylor_green_study, ConvergenceTaylorGreen, std::vector<int>{16, 32, 64, 128}, 1.0, 0.0, 100.0)
    ->Iterations(1)
    ->Unit(benchmark::kSecond);
BENCHMARK_CAPTURE(taylor_green_study, ConvergenceTaylorGreenViscous, std::vector<int>{16, 32, 64, 128}, 1.0, 10.0, 100.0)
    ->Iterations(1)
    ->Unit(benchmark::kSecond);
BENCHMARK_CAPTURE(periodic_taylor_green_study, ConvergencePeriodicTaylorGreen, std::vector<int>{32, 64, 128, 256}, 1.0, 0.0, 100.0)
    ->Iterations(1)
    ->Unit(benchmark::kSecond);
BENCHMARK_CAPTURE(periodic_taylor_green_study, ConvergencePeriodicTaylorGreenViscous, std::vector<int>{32, 64, 128, 256}, 1.0, 10.0, 100.0)
    ->Iterations(1)
    ->Unit(benchmark::kSecond);
BENCHMARK_CAPTURE(periodic_translation_study, ConvergencePeriodicTranslation, std::vector<int>{32, 64, 128, 256}, 0.8)
    ->Iterations(1)
    ->Unit(benchmark::kSecond);
BENCHMARK_CAPTURE(periodic_translation_peak, PeriodicTranslationPeak, std::vector<int>{64, 128, 256}, 0.8, true)
    ->Iterations(1)
    ->Unit(benchmark::kSecond);
BENCHMARK_CAPTURE(periodic_translation_peak, PeriodicTranslationPeakAlongX, std::vector<int>{64, 128, 256}, 0.8, false)
    ->Iterations(1)
    ->Unit(benchmark::kSecond);
BENCHMARK_CAPTURE(periodic_taylor_green_study, SmokePeriodic, std::vector<int>{16, 32}, 1.0, 10.0, 20.0)->Iterations(1)->Unit(benchmark::kSecond);
BENCHMARK_CAPTURE(thermal_study, ConvergenceThermal, std::vector<int>{32, 64, 128}, 256, 1.0)->Iterations(1)->Unit(benchmark::kSecond);

BENCHMARK_CAPTURE(bryan_fritsch_study, ConvergenceBryanFritsch, std::vector<int>{25, 50, 100}, 200, 1.0)
    ->Iterations(1)
    ->Unit(benchmark::kSecond);
// 400 / 200 / 100 / 50 m against a 25 m run, the default scheme only (about 6 min of CPU).
BENCHMARK_CAPTURE(bryan_fritsch_study, ConvergenceBryanFritsch25, std::vector<int>{25, 50, 100, 200}, 400, 1.0, false)
    ->Iterations(1)
    ->Unit(benchmark::kSecond);
BENCHMARK_CAPTURE(bryan_fritsch_study, ConvergenceBryanFritschViscous25, std::vector<int>{25, 50, 100, 200}, 400, 1.0, false,
                  &kBryanFritschViscous)
    ->Iterations(1)
    ->Unit(benchmark::kSecond);
BENCHMARK_CAPTURE(density_current_study, DensityCurrent_200, 200.0)->Iterations(1)->Unit(benchmark::kSecond);
BENCHMARK_CAPTURE(density_current_study, DensityCurrent_100, 100.0)->Iterations(1)->Unit(benchmark::kSecond);

BENCHMARK_MAIN();

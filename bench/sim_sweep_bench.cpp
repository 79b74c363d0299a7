// Error against run time for the cloud solver: sweeps of the pressure
// tolerance, the advection scheme and the resolution on one fixed short
// cumulus case, each printed as a Markdown table (docs/solver.md "Sweeps").
//
// Case: a closed 2560 m cube, a 2 K cos^2 bubble (radius 400 m, centre 600 m
// up) in a nearly saturated, conditionally unstable sounding under an
// inversion at 1800 m; anelastic, moist; `kSteps` steps of `kStepDt` s.
// Error: the RMS difference of cloud water (kg/kg) from the reference run
// (the tightest tolerance, or the finest grid box-averaged onto the coarser
// grid), relative to the reference's RMS cloud water; the same for the
// cell-centred vertical velocity w.
//
// Run:   build/bench/sim_sweep_bench --benchmark_filter=Sweep
//        (SweepTolerance_64, SweepScheme_64, SweepResolution; Smoke for CI < 2 s)
#include "atlas/sim/simulation.h"

#include <benchmark/benchmark.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

using namespace atlas::sim;

namespace {

constexpr double kSide = 2560;  // m
constexpr double kStepDt = 10;  // s per step

struct RunResult {
    double seconds_per_step = 0;
    double div_l2 = 0, div_max = 0; // worst over the steps, 1/s
    double iterations = 0;          // pressure iterations per substep
    double water_drift = 0;         // worst |relative drift| across the saturation adjustment
    double max_qc = 0, max_w = 0;
    int substeps = 0;
    int n = 0;
    std::vector<float> qc, w; // cloud water (kg/kg), cell-centred w (m/s) after the last step
};

RunResult run_case(int n, AdvectionScheme scheme, double tolerance, int steps) {
    GridSpec s;
    s.nx = s.ny = s.nz = n;
    s.dx = kSide / n;
    Sounding snd;
    snd.surface_theta = 295;
    snd.theta_lapse = 0.003;
    snd.surface_rh = 0.99;
    snd.rh_lapse = 0;
    snd.inversion_height = 1800;
    snd.inversion_jump = 6;
    snd.theta_lapse_above = 0.008;
    snd.rh_above = 0.4;
    SimOptions o;
    o.scheme = scheme;
    o.projection.tolerance = tolerance;
    o.projection.max_iterations = 500;
    Simulation sim(s, snd, o);
    std::vector<float> d(s.cells(), 0.f);
    for (int k = 0; k < n; ++k)
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i) {
                const double x = (i + 0.5) * s.dx - kSide / 2, y = (j + 0.5) * s.dx - kSide / 2, z = (k + 0.5) * s.dx - 600;
                const double l = std::sqrt(x * x + y * y + z * z) / 400;
                if (l < 1) d[(size_t(k) * n + j) * n + i] = float(2 * std::pow(std::cos(0.5 * M_PI * l), 2));
            }
    sim.add_theta(d);
    RunResult r;
    r.n = n;
    int iters = 0;
    const auto t0 = std::chrono::steady_clock::now();
    for (int step = 0; step < steps; ++step) {
        const StepReport rep = sim.step(kStepDt);
        r.div_l2 = std::max(r.div_l2, rep.divergence.l2);
        r.div_max = std::max(r.div_max, rep.divergence.max);
        r.water_drift = std::max(r.water_drift, std::fabs(rep.water_drift));
        r.max_qc = std::max(r.max_qc, rep.max_qc);
        r.max_w = std::max(r.max_w, rep.max_w);
        r.substeps += rep.substeps;
        iters += rep.pressure_iterations;
    }
    r.seconds_per_step = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() / steps;
    r.iterations = r.substeps ? double(iters) / r.substeps : 0;
    r.qc = sim.qc();
    const atlas::Field3D v = sim.velocity_field();
    r.w.assign(v.channel(2).begin(), v.channel(2).end());
    return r;
}

// The fine field averaged over blocks onto the coarse grid (n_fine a multiple of n_coarse).
std::vector<float> box_average(const std::vector<float>& fine, int nf, int nc) {
    const int f = nf / nc;
    std::vector<float> out(size_t(nc) * nc * nc, 0.f);
    for (int k = 0; k < nf; ++k)
        for (int j = 0; j < nf; ++j)
            for (int i = 0; i < nf; ++i)
                out[(size_t(k / f) * nc + j / f) * nc + i / f] += fine[(size_t(k) * nf + j) * nf + i];
    for (float& v : out) v /= float(f * f * f);
    return out;
}

// RMS(a - ref) / RMS(ref); 0 when the reference has no cloud and neither has a.
double relative_error(const std::vector<float>& a, const std::vector<float>& ref) {
    double e = 0, m = 0;
    for (size_t i = 0; i < a.size(); ++i) {
        e += (double(a[i]) - ref[i]) * (double(a[i]) - ref[i]);
        m += double(ref[i]) * ref[i];
    }
    return m > 0 ? std::sqrt(e / m) : std::sqrt(e / double(a.size()));
}

void print_header(const char* title, const char* first) {
    std::printf("\n%s\n\n| %s | s/step | substeps | CG it./substep | div L2 (1/s) | div max (1/s) | water drift | max w (m/s) | max qc (g/kg) | qc error vs ref | w error vs ref |\n"
                "|---|---|---|---|---|---|---|---|---|---|---|\n",
                title, first);
}

void print_row(const std::string& label, const RunResult& r, double err, double werr) {
    std::printf("| %s | %.3f | %d | %.1f | %.2e | %.2e | %.1e | %.2f | %.3f | %.2e | %.2e |\n", label.c_str(), r.seconds_per_step, r.substeps,
                r.iterations, r.div_l2, r.div_max, r.water_drift, r.max_w, r.max_qc * 1e3, err, werr);
    std::fflush(stdout);
}

void tolerance_sweep(benchmark::State& state, int n, int steps) {
    for (auto _ : state) {
        const std::vector<double> tols = {1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8};
        std::vector<RunResult> runs;
        for (double t : tols) runs.push_back(run_case(n, AdvectionScheme::MacCormack, t, steps));
        char title[160];
        std::snprintf(title, sizeof title, "Pressure tolerance sweep: %d^3, MacCormack, %d steps of %.0f s; reference = tolerance 1e-8", n, steps,
                      kStepDt);
        print_header(title, "tolerance");
        for (size_t i = 0; i < tols.size(); ++i) {
            char label[32];
            std::snprintf(label, sizeof label, "%.0e", tols[i]);
            print_row(label, runs[i], relative_error(runs[i].qc, runs.back().qc), relative_error(runs[i].w, runs.back().w));
        }
        state.counters["err_tol_1e-2"] = relative_error(runs.front().qc, runs.back().qc);
    }
}

void scheme_sweep(benchmark::State& state, int n, int ref_n, int steps) {
    for (auto _ : state) {
        const RunResult ref = run_case(ref_n, AdvectionScheme::MacCormack, 1e-6, steps);
        const std::vector<float> ref_c = box_average(ref.qc, ref_n, n), ref_w = box_average(ref.w, ref_n, n);
        const RunResult sl = run_case(n, AdvectionScheme::SemiLagrangian, 1e-6, steps);
        const RunResult mc = run_case(n, AdvectionScheme::MacCormack, 1e-6, steps);
        char title[200];
        std::snprintf(title, sizeof title,
                      "Advection scheme sweep: %d^3, tolerance 1e-6, %d steps of %.0f s; reference = MacCormack at %d^3 box-averaged to %d^3",
                      n, steps, kStepDt, ref_n, n);
        print_header(title, "scheme");
        print_row("semi-Lagrangian", sl, relative_error(sl.qc, ref_c), relative_error(sl.w, ref_w));
        print_row("MacCormack (limited)", mc, relative_error(mc.qc, ref_c), relative_error(mc.w, ref_w));
        print_row("reference " + std::to_string(ref_n) + "^3 MacCormack", ref, 0.0, 0.0);
        state.counters["err_sl"] = relative_error(sl.qc, ref_c);
        state.counters["err_mc"] = relative_error(mc.qc, ref_c);
    }
}

void resolution_sweep(benchmark::State& state, std::vector<int> sizes, int steps) {
    for (auto _ : state) {
        std::vector<RunResult> runs;
        for (int n : sizes) runs.push_back(run_case(n, AdvectionScheme::MacCormack, 1e-6, steps));
        const RunResult& ref = runs.back();
        char title[200];
        std::snprintf(title, sizeof title,
                      "Resolution sweep: MacCormack, tolerance 1e-6, %d steps of %.0f s; reference = the %d^3 run box-averaged to each grid",
                      steps, kStepDt, ref.n);
        print_header(title, "grid");
        for (const RunResult& r : runs) {
            const double err = r.n == ref.n ? 0.0 : relative_error(r.qc, box_average(ref.qc, ref.n, r.n));
            const double werr = r.n == ref.n ? 0.0 : relative_error(r.w, box_average(ref.w, ref.n, r.n));
            print_row(std::to_string(r.n) + "^3 (dx " + std::to_string(int(kSide / r.n)) + " m)", r, err, werr);
        }
    }
}

} // namespace

// CI smoke (< 2 s): every sweep on tiny grids, few steps.
BENCHMARK_CAPTURE(tolerance_sweep, Smoke, 16, 3)->Iterations(1)->Unit(benchmark::kSecond);
BENCHMARK_CAPTURE(scheme_sweep, Smoke, 8, 16, 3)->Iterations(1)->Unit(benchmark::kSecond);
BENCHMARK_CAPTURE(resolution_sweep, Smoke, std::vector<int>{8, 16}, 3)->Iterations(1)->Unit(benchmark::kSecond);
// The tables in docs/solver.md.
BENCHMARK_CAPTURE(tolerance_sweep, SweepTolerance_64, 64, 12)->Iterations(1)->Unit(benchmark::kSecond);
BENCHMARK_CAPTURE(scheme_sweep, SweepScheme_64, 64, 128, 12)->Iterations(1)->Unit(benchmark::kSecond);
BENCHMARK_CAPTURE(resolution_sweep, SweepResolution, std::vector<int>{32, 64, 128}, 12)->Iterations(1)->Unit(benchmark::kSecond);

BENCHMARK_MAIN();

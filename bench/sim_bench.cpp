// Cloud solver benchmarks: time per step at 64^3 / 128^3 (256^3 on request)
// with the divergence residual, and the dry Bryan & Fritsch (2002) case.
// Run:  build-sim/bench/sim_bench --benchmark_filter=...
#include "atlas/sim/simulation.h"
#include "atlas/sim/thermo.h"

#include <benchmark/benchmark.h>

#include <cmath>

using namespace atlas::sim;

namespace {

std::vector<float> bubble(const GridSpec& s, double a, double xc, double yc, double zc, double r) {
    std::vector<float> d(s.cells());
    for (int k = 0; k < s.nz; ++k)
        for (int j = 0; j < s.ny; ++j)
            for (int i = 0; i < s.nx; ++i) {
                double x = (i + 0.5) * s.dx, y = (j + 0.5) * s.dx, z = (k + 0.5) * s.dx;
                double l = std::sqrt(std::pow((x - xc) / r, 2) + (s.ny > 1 ? std::pow((y - yc) / r, 2) : 0.0) +
                                     std::pow((z - zc) / r, 2));
                d[(size_t(k) * s.ny + j) * s.nx + i] = l < 1 ? float(a * std::pow(std::cos(M_PI * l / 2), 2)) : 0.f;
            }
    return d;
}

// A moist warm bubble under an inversion in a closed cube of n^3 cells at 40 m;
// one iteration = one solver step of 5 s (CFL-limited substeps inside).
void CumulusStep(benchmark::State& state, int n) {
    GridSpec s;
    s.nx = s.ny = s.nz = n;
    s.dx = 5120.0 / n;
    Sounding snd;
    snd.theta_lapse = 0.003;
    snd.surface_rh = 0.9;
    snd.rh_lapse = -1e-4;
    snd.inversion_height = 3000;
    snd.inversion_jump = 4;
    SimOptions o;
    o.projection.tolerance = 1e-5;
    Simulation sim(s, snd, o);
    double L = n * s.dx;
    sim.add_theta(bubble(s, 2, L / 2, L / 2, 800, 600));
    StepReport r;
    int iters = 0, substeps = 0;
    for (auto _ : state) {
        r = sim.step(5.0);
        iters += r.pressure_iterations;
        substeps += r.substeps;
    }
    state.counters["div_max_per_s"] = r.divergence.max;
    state.counters["div_l2_per_s"] = r.divergence.l2;
    state.counters["div_max_x_dx_over_umax"] = r.max_speed > 0 ? r.divergence.max * s.dx / r.max_speed : 0.0;
    state.counters["cg_iters_per_substep"] = substeps ? double(iters) / substeps : 0.0;
    state.counters["substeps_per_step"] = double(substeps) / double(state.iterations());
    state.counters["s_advect"] = r.seconds_advect;
    state.counters["s_project"] = r.seconds_project;
    state.counters["s_thermo"] = r.seconds_thermo;
    state.counters["max_w"] = r.max_w;
}

void BM_CumulusStep_Smoke(benchmark::State& state) { CumulusStep(state, 16); }
void BM_CumulusStep_64(benchmark::State& state) { CumulusStep(state, 64); }
void BM_CumulusStep_128(benchmark::State& state) { CumulusStep(state, 128); }
void BM_CumulusStep_256(benchmark::State& state) { CumulusStep(state, 256); }

// Bryan & Fritsch (2002) dry: 20 km x 10 km, free-slip walls, 2 K cos^2
// bubble (r = 2 km, z = 2 km) in a neutral theta0 = 300 K atmosphere, to 1000 s.
void BryanFritschDry(benchmark::State& state, double dx, AdvectionScheme scheme, bool anelastic = true) {
    GridSpec s;
    s.nx = int(std::lround(20000 / dx));
    s.ny = 1;
    s.nz = int(std::lround(10000 / dx));
    s.dx = dx;
    SimOptions o;
    o.moist = false;
    o.scheme = scheme;
    o.anelastic = anelastic;
    StepReport r;
    int steps = 0;
    for (auto _ : state) {
        Simulation sim(s, Sounding{}, o);
        sim.add_theta(bubble(s, 2, 10000, 0, 2000, 2000));
        steps = 0;
        while (sim.time() < 1000 - 1e-9) {
            r = sim.step(std::min(5.0, 1000 - sim.time()));
            steps += r.substeps;
        }
    }
    state.counters["max_w"] = r.max_w;
    state.counters["max_theta_p"] = r.max_theta_perturbation;
    state.counters["substeps"] = steps;
    state.counters["div_max_per_s"] = r.divergence.max;
}
void BM_BryanFritschDry_100m(benchmark::State& state) { BryanFritschDry(state, 100, AdvectionScheme::MacCormack); }
void BM_BryanFritschDry_200m(benchmark::State& state) { BryanFritschDry(state, 200, AdvectionScheme::MacCormack); }
void BM_BryanFritschDry_100m_SL(benchmark::State& state) { BryanFritschDry(state, 100, AdvectionScheme::SemiLagrangian); }
void BM_BryanFritschDry_100m_Boussinesq(benchmark::State& state) { BryanFritschDry(state, 100, AdvectionScheme::MacCormack, false); }
void BM_BryanFritschDry_200m_Boussinesq(benchmark::State& state) { BryanFritschDry(state, 200, AdvectionScheme::MacCormack, false); }

// Bryan & Fritsch (2002) moist: saturated moist-neutral atmosphere with
// theta_e = 320 K and total water 0.020 kg/kg (built with this model's own
// reversible adjustment so it is neutral for the model), a cos^2 bubble whose
// theta_l increment gives theta_e' = 2 K at its centre, no rain, to 1000 s.
void BryanFritschMoist(benchmark::State& state, double dx) {
    const double qt = 0.020;
    auto theta_e_at = [&](double thl, double p) {
        AdjustResult a = saturation_adjust(thl, qt, 0, p);
        return equivalent_potential_temperature(a.theta * exner(p), p, a.qv, qt);
    };
    double lo = 250, hi = 330; // theta_l with theta_e(surface) = 320 K
    for (int i = 0; i < 80; ++i) {
        double mid = 0.5 * (lo + hi);
        (theta_e_at(mid, 1e5) < 320 ? lo : hi) = mid;
    }
    GridSpec s;
    s.nx = int(std::lround(20000 / dx));
    s.ny = 1;
    s.nz = int(std::lround(10000 / dx));
    s.dx = dx;
    Sounding snd;
    snd.surface_theta = 0.5 * (lo + hi);
    snd.total_water = qt;
    SimOptions o;
    StepReport r;
    double max_the = 0;
    for (auto _ : state) {
        Simulation sim(s, snd, o);
        const ReferenceProfile& ref = sim.reference();
        int kc = int(2000 / dx);
        double pc = ref.pressure[size_t(kc)], thl_c = snd.surface_theta;
        double dlo = 0, dhi = 5; // theta_l increment giving theta_e' = 2 K at the bubble centre
        for (int i = 0; i < 60; ++i) {
            double mid = 0.5 * (dlo + dhi);
            (theta_e_at(thl_c + mid, pc) - theta_e_at(thl_c, pc) < 2 ? dlo : dhi) = mid;
        }
        std::vector<float> shape = bubble(s, 1.0, 10000, 0, 2000, 2000);
        for (int k = 0; k < s.nz; ++k)
            for (int i = 0; i < s.nx; ++i) {
                size_t c = size_t(k) * s.nx + i;
                if (shape[c] <= 0) continue;
                double pi = ref.exner[size_t(k)];
                double thl = sim.theta()[c] - kLv / (kCp * pi) * sim.qc()[c] + dlo * shape[c];
                AdjustResult a = saturation_adjust(thl, qt, 0, ref.pressure[size_t(k)]);
                sim.theta()[c] = float(a.theta);
                sim.qv()[c] = float(a.qv);
                sim.qc()[c] = float(a.qc);
            }
        while (sim.time() < 1000 - 1e-9) r = sim.step(std::min(5.0, 1000 - sim.time()));
        max_the = -1e30;
        for (int k = 0; k < s.nz; ++k) {
            double p = ref.pressure[size_t(k)], pi = ref.exner[size_t(k)];
            double the0 = equivalent_potential_temperature(ref.theta[size_t(k)] * pi, p, ref.qv[size_t(k)], qt);
            for (int i = 0; i < s.nx; ++i) {
                size_t c = size_t(k) * s.nx + i;
                double qtc = double(sim.qv()[c]) + sim.qc()[c];
                max_the = std::max(max_the, equivalent_potential_temperature(sim.theta()[c] * pi, p, sim.qv()[c], qtc) - the0);
            }
        }
    }
    state.counters["max_w"] = r.max_w;
    state.counters["max_theta_e_p"] = max_the;
    state.counters["water_drift"] = r.water_drift;
    state.counters["div_max_per_s"] = r.divergence.max;
}
void BM_BryanFritschMoist_100m(benchmark::State& state) { BryanFritschMoist(state, 100); }
void BM_BryanFritschMoist_200m(benchmark::State& state) { BryanFritschMoist(state, 200); }

} // namespace

BENCHMARK(BM_BryanFritschMoist_100m)->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK(BM_BryanFritschMoist_200m)->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK(BM_CumulusStep_Smoke)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_CumulusStep_64)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_CumulusStep_128)->Unit(benchmark::kMillisecond)->Iterations(2);
BENCHMARK(BM_CumulusStep_256)->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK(BM_BryanFritschDry_100m)->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK(BM_BryanFritschDry_200m)->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK(BM_BryanFritschDry_100m_SL)->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK(BM_BryanFritschDry_100m_Boussinesq)->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK(BM_BryanFritschDry_200m_Boussinesq)->Unit(benchmark::kMillisecond)->Iterations(1);

BENCHMARK_MAIN();

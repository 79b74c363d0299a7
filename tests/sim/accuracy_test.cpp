// Accuracy of the time stepping (TimeScheme::Trapezoidal), the step control and
// the water honesty rules (no silent clamping). References are analytic: the
// Taylor-Green vortex is an exact steady (inviscid) or exponentially decaying
// (viscous) solution; the full study is bench/sim_convergence_bench.cpp.
#include "atlas/sim/simulation.h"

#include "atlas/core/error.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numeric>
#include <string>

using namespace atlas::sim;

namespace {

struct Norms {
    double l2 = 0, max = 0;
};

// u = U sin(kx) cos(kz), w = -U cos(kx) sin(kz), k = pi / L, in a closed
// free-slip slab: exact, discretely divergence-free on the MAC grid.
Norms taylor_green_error(int n, TimeScheme ts, double nu, double T) {
    const double L = 1000, U = 10, k = M_PI / L;
    GridSpec s;
    s.nx = n, s.ny = 1, s.nz = n, s.dx = L / n;
    SimOptions o;
    o.anelastic = false;
    o.moist = false;
    o.time_scheme = ts;
    o.viscosity = nu;
    o.step_error_tolerance = 0; // the order at a fixed CFL number
    o.max_substeps = 1000;
    o.projection.tolerance = 1e-10;
    o.projection.max_iterations = 1000;
    Simulation sim(s, Sounding{}, o);
    MacVelocity& v = sim.velocity();
    auto f = [&](double x, double z) { return U * std::sin(k * x) * std::cos(k * z); };
    for (int c = 0; c < n; ++c)
        for (int i = 0; i <= n; ++i) {
            v.u[v.iu(i, 0, c)] = float(f(i * s.dx, (c + 0.5) * s.dx));
            v.w[v.iw(c, 0, i)] = float(-f(i * s.dx, (c + 0.5) * s.dx)); // w(x_c, z_i) = -U cos(k x_c) sin(k z_i)
        }
    sim.step(T);
    const double a = std::exp(-2 * nu * k * k * T);
    Norms e;
    double sum2 = 0;
    size_t cnt = 0;
    for (int c = 0; c < n; ++c)
        for (int i = 0; i <= n; ++i) {
            const double du = sim.velocity().u[v.iu(i, 0, c)] - a * f(i * s.dx, (c + 0.5) * s.dx);
            const double dw = sim.velocity().w[v.iw(c, 0, i)] + a * f(i * s.dx, (c + 0.5) * s.dx);
            sum2 += du * du + dw * dw;
            cnt += 2;
            e.max = std::max({e.max, std::fabs(du), std::fabs(dw)});
        }
    e.l2 = std::sqrt(sum2 / double(cnt));
    return e;
}

GridSpec column(int nx, int nz, double dx) {
    GridSpec s;
    s.nx = nx, s.ny = 1, s.nz = nz, s.dx = dx;
    return s;
}

} // namespace

// The default stepping is second order on a smooth flow through advection,
// projection and explicit viscosity together (measured 2.40 / 2.16 inviscid
// from 16 to 32 cells); the old split is first order (0.82).
TEST(SimAccuracy, TaylorGreenConvergesAtSecondOrder) {
    for (double nu : {0.0, 10.0}) {
        const Norms c = taylor_green_error(16, TimeScheme::Trapezoidal, nu, 100), f = taylor_green_error(32, TimeScheme::Trapezoidal, nu, 100);
        EXPECT_GE(std::log2(c.l2 / f.l2), 1.8) << "nu " << nu << ": " << c.l2 << " -> " << f.l2;
        EXPECT_GE(std::log2(c.max / f.max), 1.8) << "nu " << nu << ": " << c.max << " -> " << f.max;
    }
    const Norms c = taylor_green_error(16, TimeScheme::Split, 0, 100), f = taylor_green_error(32, TimeScheme::Split, 0, 100);
    EXPECT_LT(std::log2(c.l2 / f.l2), 1.3) << "the split scheme is expected to be first order";
}

// Negative water written into the state is refused, not clamped (clamping adds water).
TEST(SimAccuracy, NegativeWaterInTheStateIsRefused) {
    SimOptions o;
    o.moist = false;
    Simulation sim(column(8, 8, 100), Sounding{}, o);
    sim.qv()[5] = -1e-6f;
    try {
        sim.step(1);
        FAIL() << "negative qv accepted";
    } catch (const atlas::Error& e) {
        EXPECT_NE(std::string(e.what()).find("qv"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("cell 5"), std::string::npos) << e.what();
    }
    EXPECT_EQ(sim.time(), 0.0);
}

// A vapour sink larger than the vapour present takes what is there and
// reports the rest; the water lost equals exactly what the cell held.
TEST(SimAccuracy, VapourSinkTakesOnlyWhatIsThereAndReportsTheDeficit) {
    Sounding snd;
    snd.surface_rh = 0.5;
    SimOptions o;
    o.moist = false; // no condensation: the sink is the only change at rest
    Simulation sim(column(8, 8, 100), snd, o);
    const size_t cell = 3 * 8 + 4;
    const double held = sim.qv()[cell];
    ASSERT_GT(held, 1e-4);
    const double before = std::accumulate(sim.qv().begin(), sim.qv().end(), 0.0);
    std::vector<float> heat(64, 0.f), vap(64, 0.f);
    const double dt = 0.01; // short: the buoyancy of the drier cell moves nothing measurable
    vap[cell] = float(-3 * held / dt); // 3x the vapour present over the step
    sim.set_sources(heat, vap);
    const StepReport r = sim.step(dt);
    EXPECT_EQ(sim.qv()[cell], 0.f);
    const double after = std::accumulate(sim.qv().begin(), sim.qv().end(), 0.0);
    EXPECT_NEAR(before - after, held, 1e-6 * held);
    EXPECT_NEAR(r.vapour_sink_deficit, 2 * held, 1e-5 * held);
}

// Cooling emitters: a negative heat rate lowers theta by rate * dt at rest.
TEST(SimAccuracy, CoolingSourceLowersTheta) {
    SimOptions o;
    o.moist = false;
    Simulation sim(column(8, 8, 100), Sounding{}, o);
    std::vector<float> heat(64, 0.f);
    heat[20] = -0.01f;
    sim.set_sources(heat, {});
    sim.step(2.0);
    EXPECT_NEAR(sim.theta_perturbation().channel(0)[20], -0.02, 2e-4);
}

// Diffusion of qv' = qv - qv0(z) in a dry column makes qv negative where qv0 is
// convex; the negatives are moved to the wet cells of the slice and reported.
TEST(SimAccuracy, DiffusionNegativesAreRedistributedAndReported) {
    Sounding snd;
    snd.surface_rh = 0.9;
    SimOptions o;
    o.moist = false;
    o.diffusivity = 500;
    Simulation sim(column(8, 16, 100), snd, o);
    for (size_t c = 0; c < sim.qv().size(); ++c)
        if (c % 8 != 0) sim.qv()[c] = 0.f; // one wet cell per row
    const StepReport r = sim.step(2.0);
    for (float q : sim.qv()) ASSERT_GE(q, 0.f);
    EXPECT_GT(r.water_redistributed, 0.0);
}

// The accuracy control keeps the embedded error estimate near its tolerance
// and takes more substeps than the CFL limit alone; it reports what limited dt.
TEST(SimAccuracy, StepControlBoundsTheEmbeddedErrorEstimate) {
    auto run = [](double tol, double& worst, int& substeps, std::string& limit) {
        GridSpec s = column(32, 32, 62.5);
        SimOptions o;
        o.moist = false;
        o.cfl = 2;
        o.max_substeps = 1000;
        o.step_error_tolerance = tol;
        Simulation sim(s, Sounding{}, o);
        std::vector<float> d(s.cells(), 0.f);
        for (int k = 0; k < 32; ++k)
            for (int i = 0; i < 32; ++i) {
                const double r = std::hypot((i + 0.5) * 62.5 - 1000, (k + 0.5) * 62.5 - 500) / 300;
                if (r < 1) d[size_t(k) * 32 + i] = float(2 * std::pow(std::cos(0.5 * M_PI * r), 2));
            }
        sim.add_theta(d);
        worst = 0, substeps = 0;
        for (int st = 0; st < 12; ++st) {
            const StepReport r = sim.step(20);
            if (st >= 2) worst = std::max(worst, r.step_error);
            substeps += r.substeps;
            if (std::string(r.dt_limit) == "accuracy") limit = "accuracy";
        }
    };
    double free_err = 0, ctl_err = 0;
    int free_sub = 0, ctl_sub = 0;
    std::string free_lim, ctl_lim;
    run(0, free_err, free_sub, free_lim);
    run(0.005, ctl_err, ctl_sub, ctl_lim);
    EXPECT_GT(free_err, 0.005) << "the uncontrolled run should exceed the tolerance for this test to mean anything";
    EXPECT_LT(ctl_err, 1.5 * 0.005);
    EXPECT_GT(ctl_sub, free_sub);
    EXPECT_EQ(ctl_lim, "accuracy");
    EXPECT_EQ(free_lim, "") << "no accuracy limit without a tolerance";
    std::printf("step control: worst error %.4f cells in %d substeps uncontrolled, %.4f in %d with tolerance 0.005\n", free_err,
                free_sub, ctl_err, ctl_sub);
}

// The documented cell-size range and the check agree: dx up to 1e5 m is a
// valid grid, a Simulation refuses a top cell centre above the modelled
// atmosphere (Exner 0.05: z = 0.95 c_p theta / g = 29.18 km for neutral 300 K,
// analytic since Exner is linear in z there) and names that height.
TEST(SimAccuracy, CellSizeRangeMatchesTheModelledAtmosphere) {
    GridSpec big = column(4, 2, 1e5);
    EXPECT_NO_THROW(big.validate());
    SimOptions o;
    o.moist = false;
    const double ztop = 0.95 * 1004.5 * 300 / 9.81;
    EXPECT_NO_THROW(Simulation(column(4, 2, ztop / 1.5 * 0.999), Sounding{}, o));
    try {
        Simulation sim(column(4, 2, ztop / 1.5 * 1.001), Sounding{}, o);
        FAIL() << "a top cell above the model top was accepted";
    } catch (const atlas::Error& e) {
        const std::string m = e.what();
        EXPECT_NE(m.find("at z = " + std::to_string(long(std::lround(ztop))) + " m"), std::string::npos) << m; // the analytic top
    }
}

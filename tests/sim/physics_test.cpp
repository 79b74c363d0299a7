// Analytic checks of the solver's physics (reference state, buoyancy and the
// anelastic projection) and the Robert (1993) dry rising thermal.
#include "atlas/sim/simulation.h"
#include "atlas/sim/thermo.h"

#include "atlas/core/error.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

using namespace atlas;
using namespace atlas::sim;

namespace {
GridSpec slab(int nx, int nz, double dx, BoundarySet b = all_closed()) {
    GridSpec s;
    s.nx = nx;
    s.ny = 1;
    s.nz = nz;
    s.dx = dx;
    s.boundary = b;
    return s;
}
} // namespace

// Neutral reference (theta0 = const): the hydrostatic Exner function is exactly
// linear, Pi(z) = Pi_s - g z / (c_p theta0); checked to round-off. A stable
// profile with a kinked inversion is checked against an independent Simpson
// quadrature of dPi/dz = -g / (c_p theta(z)) (4000 panels per cell) to 1e-9,
// and p, rho against the gas law and p = p00 Pi^(c_p/R_d) to round-off.
TEST(SimPhysics, ReferenceStateIsHydrostatic) {
    Sounding neutral;
    ReferenceProfile r = make_reference(neutral, 100, 100.0);
    const double pis = exner(neutral.surface_pressure);
    for (int k = 0; k < 100; ++k) {
        double z = (k + 0.5) * 100.0;
        EXPECT_NEAR(r.exner[size_t(k)], pis - kGravity * z / (kCp * 300.0), 1e-12) << k;
    }
    Sounding stable;
    stable.theta_lapse = 0.005;
    stable.inversion_height = 3000;
    stable.inversion_jump = 3;
    stable.inversion_depth = 500;
    stable.theta_lapse_above = 0.003;
    r = make_reference(stable, 100, 100.0);
    double pi = pis, z = 0;
    for (int k = 0; k < 100; ++k) {
        const double zc = (k + 0.5) * 100.0, h = (zc - z) / 4000;
        auto f = [&](double zz) { return kGravity / (kCp * stable.theta_at(zz)); };
        double sum = f(z) + f(zc);
        for (int m = 1; m < 4000; ++m) sum += (m % 2 ? 4 : 2) * f(z + m * h);
        pi -= sum * h / 3;
        z = zc;
        EXPECT_NEAR(r.exner[size_t(k)], pi, 1e-9) << k;
        EXPECT_NEAR(r.pressure[size_t(k)], kP00 * std::pow(r.exner[size_t(k)], kCp / kRd), 1e-9 * r.pressure[size_t(k)]);
        EXPECT_NEAR(r.rho[size_t(k)] * kRd * r.theta[size_t(k)] * r.exner[size_t(k)], r.pressure[size_t(k)],
                    1e-9 * r.pressure[size_t(k)]);
    }
}

// A uniform buoyant disk in a large 2D Boussinesq box: after one projection the
// fluid inside moves up at exactly half the free acceleration, B dt / 2 (the
// 2D induced mass of a fluid cylinder equals its displaced mass; the 3D sphere
// has 2/3). Tolerance 3 % for the staircase disk (radius 12 cells) and the
// walls 10 radii away.
TEST(SimPhysics, UniformBuoyantDiskAcceleratesAtHalfItsBuoyancy) {
    const int n = 240;
    GridSpec s = slab(n, n, 1.0);
    const double R = 12, xc = n / 2.0, zc = n / 2.0, Bdt = 1.0;
    auto inside = [&](int i, int k) { return std::hypot(i + 0.5 - xc, k + 0.5 - zc) < R; };
    MacVelocity v(s);
    for (int k = 1; k < n; ++k)
        for (int i = 0; i < n; ++i) v.w[v.iw(i, 0, k)] = float(0.5 * Bdt * (inside(i, k - 1) + inside(i, k)));
    PressureSolver solver(s);
    ProjectionOptions o;
    o.tolerance = 1e-9;
    ProjectionReport rep = solver.project(v, o);
    ASSERT_TRUE(rep.converged);
    double centre = v.w[v.iw(n / 2, 0, n / 2)];
    std::printf("[sim] uniform disk: w / (B dt) = %.4f at the centre (analytic 0.5)\n", centre / Bdt);
    EXPECT_NEAR(centre / Bdt, 0.5, 0.015);
    // Uniform inside: the faces within R/2 of the centre within 3 % of the centre value.
    for (int k = n / 2 - int(R / 2); k <= n / 2 + int(R / 2); ++k)
        for (int i = n / 2 - int(R / 2); i <= n / 2 + int(R / 2); ++i)
            if (std::hypot(i + 0.5 - xc, k - zc) < R / 2) {
                EXPECT_NEAR(v.w[v.iw(i, 0, k)], centre, 0.03 * centre) << i << " " << k;
            }
}

// Horizontally uniform buoyancy in a column open at top and bottom. Boussinesq:
// the column accelerates at exactly g theta' / theta0. Anelastic: the
// projection must give rho0 w = C at every w face with C = sum(w*) / sum(1/rho0)
// (phi = 0 in both ghost cells), which checks that rho0 sits at the faces in
// both the divergence and the gradient. Tolerance 1e-6 relative (solver 1e-10).
TEST(SimPhysics, UniformBuoyantColumnAcceleratesAtGThetaPrimeOverTheta0) {
    BoundarySet b = all_closed();
    b[4] = b[5] = Boundary::Open;
    GridSpec s = slab(8, 64, 100.0, b);
    SimOptions o;
    o.moist = false;
    o.anelastic = false;
    o.projection.tolerance = 1e-10;
    Simulation sim(s, Sounding{}, o);
    sim.add_theta(std::vector<float>(s.cells(), 0.5f));
    StepReport r = sim.step(4.0);
    const double expect = 4.0 * kGravity * 0.5 / 300.0;
    for (float w : sim.velocity().w) ASSERT_NEAR(w, expect, 1e-6 * expect);
    EXPECT_NEAR(r.max_w, expect, 1e-6 * expect);

    // Anelastic projection of a uniform w* = 1 m/s.
    ReferenceProfile ref = make_reference(Sounding{}, 64, 100.0);
    PressureSolver solver(s, ref.rho);
    MacVelocity v(s);
    std::fill(v.w.begin(), v.w.end(), 1.f);
    ProjectionOptions po;
    po.tolerance = 1e-10;
    ASSERT_TRUE(solver.project(v, po).converged);
    const std::vector<double>& rf = solver.rho_face();
    double inv = 0;
    for (double x : rf) inv += 1 / x;
    const double C = double(rf.size()) / inv;
    for (int k = 0; k <= s.nz; ++k)
        for (int i = 0; i < s.nx; ++i) ASSERT_NEAR(rf[size_t(k)] * v.w[v.iw(i, 0, k)], C, 1e-6 * C) << k;
}

// Robert (1993) dry rising thermal, set up as published: 1000 m x 1000 m slab,
// theta0 = 300 K neutral, a 0.5 K bubble of radius 250 m with a Gaussian edge
// (e-folding 100 m) centred at (500, 260) m; 10 m cells, anelastic, 600 s.
// Checked: (1) the start: w_max(20 s) lies between 0.25 and 0.5 of B t,
// B = g 0.5 / 300 (0.5 is the unbounded uniform disk above; the walls 1.5 radii
// away and the Gaussian edge can only lower it); (2) the monotone advection
// keeps 0 <= theta' <= 0.5 K; (3) the thermal (theta' > 0.1 K) centroid rises
// by 250..550 m in 600 s and the peak w stays within 2..5 m/s
// (sqrt(2 B 500 m) = 4 m/s is the undiluted-parcel bound for that rise). These
// bands are ours, not Robert's figures (not at hand); the values are printed
// and recorded in docs/solver.md.
TEST(SimPhysics, RobertRisingThermal) {
    GridSpec s = slab(100, 100, 10.0);
    SimOptions o;
    o.moist = false;
    Simulation sim(s, Sounding{}, o);
    std::vector<float> d(s.cells());
    for (int k = 0; k < s.nz; ++k)
        for (int i = 0; i < s.nx; ++i) {
            double r = std::hypot((i + 0.5) * 10 - 500, (k + 0.5) * 10 - 260);
            d[size_t(k) * s.nx + i] = float(r <= 250 ? 0.5 : 0.5 * std::exp(-std::pow((r - 250) / 100, 2)));
        }
    sim.add_theta(d);
    auto centroid = [&]() {
        double m = 0, mz = 0;
        for (int k = 0; k < s.nz; ++k)
            for (int i = 0; i < s.nx; ++i) {
                double tp = sim.theta()[size_t(k) * s.nx + i] - sim.reference().theta[size_t(k)];
                if (tp > 0.1) m += tp, mz += tp * (k + 0.5) * 10;
            }
        return mz / m;
    };
    const double z0 = centroid(), B = kGravity * 0.5 / 300;
    StepReport r = sim.step(20.0);
    std::printf("[sim] Robert: w_max(20 s) / (B t) = %.4f\n", r.max_w / (B * 20));
    EXPECT_GT(r.max_w / (B * 20), 0.25);
    EXPECT_LT(r.max_w / (B * 20), 0.5);
    double wpeak = r.max_w;
    while (sim.time() < 600 - 1e-9) {
        r = sim.step(std::min(10.0, 600 - sim.time()));
        wpeak = std::max(wpeak, r.max_w);
        ASSERT_LE(r.max_theta_perturbation, 0.5 + 1e-4);
        ASSERT_GE(r.min_theta_perturbation, -1e-4);
    }
    const double rise = centroid() - z0;
    std::printf("[sim] Robert 600 s: max w %.3f m/s (peak %.3f), max theta' %.3f K, centroid rise %.0f m, div %.2g\n",
                r.max_w, wpeak, r.max_theta_perturbation, rise, r.divergence.max);
    EXPECT_GT(rise, 250);
    EXPECT_LT(rise, 550);
    EXPECT_GT(wpeak, 2.0);
    EXPECT_LT(wpeak, 5.0);
}

// Bryan & Fritsch reversible thermodynamics: the adjustment keeps theta_e and
// q_t (1e-9 relative) from any start, including far supersaturated or fully
// evaporating parcels, lands on saturation (or below with qc = 0), and the
// moist-neutral sounding has theta_e = 320 K at every level (1e-6 K) and is
// hydrostatic in theta_rho against an independent fine integration (1e-7).
TEST(SimPhysics, ReversibleThetaEAdjustmentAndSounding) {
    struct Start {
        double theta, qv, qc, p;
    } starts[] = {{300, 0.03, 0.0, 9e4}, {290, 0.0, 0.02, 8e4}, {310, 0.001, 0.001, 6e4}, {280, 0.012, 0.008, 1e5}, {350, 0.0, 0.0, 5e4}};
    for (const Start& st : starts) {
        const double pi = exner(st.p), qt = st.qv + st.qc;
        const double the0 = equivalent_potential_temperature(st.theta * pi, st.p, st.qv, qt);
        AdjustResult a = saturation_adjust_theta_e(st.theta, st.qv, st.qc, st.p);
        EXPECT_NEAR(equivalent_potential_temperature(a.theta * pi, st.p, a.qv, a.qv + a.qc), the0, 1e-9 * the0);
        EXPECT_NEAR(a.qv + a.qc, qt, 1e-15);
        EXPECT_GE(a.qc, 0);
        EXPECT_GE(a.qv, 0);
        const double qs = saturation_mixing_ratio(a.theta * pi, st.p);
        if (a.qc > 0) {
            EXPECT_NEAR(a.qv, qs, 1e-9);
        } else {
            EXPECT_LE(a.qv, qs * (1 + 1e-9));
        }
    }
    EXPECT_THROW(saturation_adjust_theta_e(std::nan(""), 0.01, 0, 1e5), Error);
    Sounding snd;
    snd.theta_e = 320;
    snd.total_water = 0.02;
    const int nz = 50;
    ReferenceProfile r = make_reference(snd, nz, 200.0);
    double pi = exner(snd.surface_pressure), z = 0;
    for (int k = 0; k < nz; ++k) {
        const double p = r.pressure[size_t(k)], e = r.exner[size_t(k)];
        EXPECT_NEAR(equivalent_potential_temperature(r.theta[size_t(k)] * e, p, r.qv[size_t(k)], 0.02), 320.0, 1e-6) << k;
        EXPECT_NEAR(r.qv[size_t(k)] + r.qc[size_t(k)], 0.02, 1e-15);
        // Independent integration: 2000 explicit Euler-midpoint steps per cell.
        const double zc = (k + 0.5) * 200, h = (zc - z) / 2000;
        for (int m = 0; m < 2000; ++m) {
            auto theta_rho = [&](double pp) {
                const double pr = kP00 * std::pow(pp, kCp / kRd);
                const double T = equilibrium_temperature_theta_e(320, pr, 0.02, 290);
                const double qv = std::min(0.02, saturation_mixing_ratio(T, pr));
                return T / pp * (1 + qv / kEps) / 1.02;
            };
            const double half = pi - 0.5 * h * kGravity / (kCp * theta_rho(pi));
            pi -= h * kGravity / (kCp * theta_rho(half));
        }
        z = zc;
        EXPECT_NEAR(e, pi, 1e-7) << k;
    }
    Sounding bad = snd;
    bad.total_water = 0;
    EXPECT_THROW(make_reference(bad, 10, 100), Error);
}

// The reversible moist-neutral atmosphere at rest stays at rest in the
// reversible model (|u| < 1e-3 m/s over 30 steps of 10 s; qc changes < 1e-6).
TEST(SimPhysics, ReversibleSaturatedNeutralAtmosphereStaysAtRest) {
    GridSpec s = slab(16, 40, 200);
    Sounding snd;
    snd.theta_e = 320;
    snd.total_water = 0.02;
    SimOptions o;
    o.reversible_theta_e = true;
    Simulation sim(s, snd, o);
    std::vector<float> qc0 = sim.qc();
    StepReport r;
    for (int n = 0; n < 30; ++n) {
        r = sim.step(10.0);
        ASSERT_LT(r.max_speed, 1e-3) << n;
    }
    double dq = 0;
    for (size_t c = 0; c < qc0.size(); ++c) dq = std::max(dq, double(std::fabs(sim.qc()[c] - qc0[c])));
    EXPECT_LT(dq, 1e-6);
}

// Bryan & Fritsch moist, coarse (200 m, 10 s steps), set up as published with
// their reversible thermodynamics: bubble theta_rho raised by theta'/300 (here
// theta_v, saturated at q_t = 0.02), theta_e = 320 K neutral sounding.
// Tolerances: max w within 2.5 m/s of the paper's 15.7 m/s (the 200 m / dt 10 s
// resolution costs ~2 m/s, see docs/solver.md); max theta_e' between 2.5 K and
// the initial peak (monotone advection cannot raise it; paper 4.10 K).
TEST(SimPhysics, BryanFritschMoistCoarse) {
    const double qt = 0.02;
    GridSpec s = slab(100, 50, 200.0);
    Sounding snd;
    snd.theta_e = 320;
    snd.total_water = qt;
    SimOptions o;
    o.reversible_theta_e = true;
    Simulation sim(s, snd, o);
    const ReferenceProfile& ref = sim.reference();
    for (int k = 0; k < s.nz; ++k)
        for (int i = 0; i < s.nx; ++i) {
            const double l = std::hypot(((i + 0.5) * 200 - 10000) / 2000, ((k + 0.5) * 200 - 2000) / 2000);
            if (l >= 1) continue;
            const size_t kk = size_t(k), c = size_t(k) * s.nx + i;
            const double pi = ref.exner[kk], p = ref.pressure[kk];
            const double target = ref.theta[kk] * (1 + 0.608 * ref.qv[kk] - ref.qc[kk]) * (1 + 2 * std::pow(std::cos(M_PI * l / 2), 2) / 300);
            double t0 = ref.theta[kk] * pi - 5, t1 = ref.theta[kk] * pi + 10;
            for (int it = 0; it < 60; ++it) {
                const double T = 0.5 * (t0 + t1), qv = std::min(qt, saturation_mixing_ratio(T, p));
                ((T / pi) * (1 + 0.608 * qv - (qt - qv)) < target ? t0 : t1) = T;
            }
            const double T = 0.5 * (t0 + t1), qv = std::min(qt, saturation_mixing_ratio(T, p));
            sim.theta()[c] = float(T / pi), sim.qv()[c] = float(qv), sim.qc()[c] = float(qt - qv);
        }
    auto max_theta_e_p = [&]() {
        double m = -1e30;
        for (int k = 0; k < s.nz; ++k)
            for (int i = 0; i < s.nx; ++i) {
                const size_t c = size_t(k) * s.nx + i;
                m = std::max(m, equivalent_potential_temperature(sim.theta()[c] * ref.exner[size_t(k)], ref.pressure[size_t(k)],
                                                                 sim.qv()[c], double(sim.qv()[c]) + sim.qc()[c]) - 320);
            }
        return m;
    };
    const double the0 = max_theta_e_p();
    StepReport r;
    while (sim.time() < 1000 - 1e-9) r = sim.step(std::min(10.0, 1000 - sim.time()));
    const double the = max_theta_e_p();
    std::printf("[sim] Bryan-Fritsch moist 200 m reversible: max w %.2f m/s, max theta_e' %.2f K (initial %.2f)\n", r.max_w, the, the0);
    EXPECT_NEAR(the0, 3.94, 0.05);
    EXPECT_NEAR(r.max_w, 15.7, 2.5);
    EXPECT_GT(the, 2.5);
    EXPECT_LE(the, the0 + 1e-3);
}

// Advection-reflection keeps kinetic energy that the plain advect-project split
// loses: a solenoidal vortex in a closed Boussinesq box (no buoyancy), 20 steps
// at CFL ~1.5. Checked: the reflected run keeps more energy than the plain one,
// and neither gains energy (KE <= KE0 (1 + 1e-3)). Energies are printed.
TEST(SimPhysics, AdvectionReflectionKeepsKineticEnergy) {
    GridSpec s = slab(48, 48, 10.0);
    auto run = [&](bool reflect) {
        SimOptions o;
        o.moist = false;
        o.anelastic = false;
        o.advection_reflection = reflect;
        o.cfl = 1.5;
        Simulation sim(s, Sounding{}, o);
        MacVelocity& v = sim.velocity();
        // Streamfunction psi = sin(pi x / L) sin(pi z / L) (sampled at nodes): u = dpsi/dz, w = -dpsi/dx.
        const double L = 480, A = 10 * L / M_PI;
        auto psi = [&](double x, double z) { return A * std::sin(M_PI * x / L) * std::sin(M_PI * z / L) * (1 + 0.3 * std::sin(3 * M_PI * x / L)); };
        for (int k = 0; k < 48; ++k)
            for (int i = 0; i <= 48; ++i) v.u[v.iu(i, 0, k)] = float((psi(i * 10.0, (k + 1) * 10.0) - psi(i * 10.0, k * 10.0)) / 10.0);
        for (int k = 0; k <= 48; ++k)
            for (int i = 0; i < 48; ++i) v.w[v.iw(i, 0, k)] = float(-(psi((i + 1) * 10.0, k * 10.0) - psi(i * 10.0, k * 10.0)) / 10.0);
        auto ke = [&]() {
            double e = 0;
            for (float x : v.u) e += 0.5 * double(x) * x;
            for (float x : v.w) e += 0.5 * double(x) * x;
            return e;
        };
        const double e0 = ke();
        for (int n = 0; n < 20; ++n) sim.step(5.0);
        return std::pair<double, double>(e0, ke());
    };
    auto [e0, plain] = run(false);
    auto [e0r, refl] = run(true);
    std::printf("[sim] vortex KE after 20 steps: plain %.4f, reflection %.4f of the initial\n", plain / e0, refl / e0r);
    EXPECT_DOUBLE_EQ(e0, e0r);
    EXPECT_GT(refl, plain);
    EXPECT_LE(refl, e0 * (1 + 1e-3));
    EXPECT_LE(plain, e0 * (1 + 1e-3));
}

// Extremes with every option on (rain, reversible theta_e, advection-reflection,
// limited cubic): a 200 m/s velocity spike is substepped and stays finite with
// rain >= 0 and the projection converged; dt 100x past CFL with a small
// substep budget is refused with an error naming max_substeps.
TEST(SimPhysics, AllOptionsSurviveAVelocitySpikeAndRefuseAHugeStep) {
    GridSpec s = slab(24, 24, 100.0);
    Sounding snd;
    snd.theta_e = 320;
    snd.total_water = 0.015;
    SimOptions o;
    o.rain = true;
    o.reversible_theta_e = true;
    o.advection_reflection = true;
    o.scheme = AdvectionScheme::CubicLimited;
    o.max_substeps = 2000;
    Simulation sim(s, snd, o);
    sim.velocity().w[sim.velocity().iw(12, 0, 12)] = 200.f;
    for (int n = 0; n < 3; ++n) {
        StepReport r = sim.step(10.0);
        ASSERT_TRUE(r.pressure_converged);
        ASSERT_TRUE(std::isfinite(r.max_speed) && std::isfinite(r.max_theta_perturbation));
        ASSERT_GT(r.substeps, 1);
        for (float q : sim.qr()) ASSERT_GE(q, 0.f);
        for (float q : sim.qc()) ASSERT_GE(q, 0.f);
    }
    SimOptions tight = o;
    tight.max_substeps = 3;
    Simulation small(s, snd, tight);
    small.velocity().w[small.velocity().iw(12, 0, 12)] = 50.f;
    try {
        small.step(1000.0);
        FAIL() << "a 1000 s step at 50 m/s on 100 m cells was accepted";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("max_substeps"), std::string::npos) << e.what();
    }
}

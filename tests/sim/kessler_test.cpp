// Kessler warm rain: rates against the formulas, boundedness at stiff dt,
// water budget with fallout, and the Simulation wiring.
#include "atlas/sim/kessler.h"
#include "atlas/sim/simulation.h"
#include "atlas/sim/thermo.h"

#include "atlas/core/error.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>

using namespace atlas;
using namespace atlas::sim;

namespace {
GridSpec column(int nz, double dz) {
    GridSpec s;
    s.nx = 2;
    s.ny = 1;
    s.nz = nz;
    s.dx = dz;
    return s;
}
struct Column {
    std::vector<float> theta, qv, qc, qr;
    std::vector<double> p, pi, rho;
    explicit Column(int nz) : theta(size_t(2 * nz), 300.f), qv(size_t(2 * nz), 0.f), qc(size_t(2 * nz), 0.f),
                              qr(size_t(2 * nz), 0.f) {
        ReferenceProfile r = make_reference(Sounding{}, nz, 100.0);
        p = r.pressure, pi = r.exner, rho = r.rho;
    }
};
} // namespace

// For a small dt (k1 dt = 1e-5) the converted amount over dt matches the
// autoconversion rate k1 (qc - a) and, with rain present, k1 (qc - a) +
// k2 qc qr^0.875, to 1e-4 relative (the exact exponential differs at O(k dt)).
TEST(SimKessler, ConvertsAtTheAnalyticRateForSmallDt) {
    GridSpec s = column(1 + 1, 100);
    KesslerOptions o;
    o.evaporation = false;
    const double dt = 0.01;
    for (double qr0 : {0.0, 2e-3}) {
        Column c(2);
        std::fill(c.qc.begin(), c.qc.end(), 3e-3f);
        std::fill(c.qr.begin(), c.qr.end(), float(qr0));
        const float qc_before = c.qc[0], qr_before = c.qr[0];
        KesslerReport r = kessler_conversions(s, c.theta, c.qv, c.qc, c.qr, c.p, c.pi, c.rho, dt, o);
        double rate = (double(c.qr[0]) - qr_before) / dt;
        double expect = 1e-3 * (double(qc_before) - 1e-3) + 2.2 * double(qc_before) * std::pow(qr0, 0.875);
        std::printf("[sim] kessler qr0 = %g: rate %.6g, analytic %.6g\n", qr0, rate, expect);
        // float resolution of qr (~2e-10 at 2e-3) over dt = 0.01 s limits the check to 2e-7 kg/kg/s absolute
        EXPECT_NEAR(rate, expect, 1e-4 * expect + 3e-7);
        EXPECT_NEAR(double(c.qc[0]) + c.qr[0], double(qc_before) + qr_before, 1e-9);
        EXPECT_GT(r.autoconverted, 0);
        if (qr0 > 0) {
            EXPECT_GT(r.accreted, 0);
        }
    }
}

// Stiff: rates x dt from 1e-2 to 1e6 stay bounded and non-negative; the
// conversion lands between the old qc and the equilibrium (qc* = k1 a /
// (k1 + k2 qr^0.875) <= a); qc + qr conserved to float rounding.
TEST(SimKessler, StiffTimeStepStaysBounded) {
    GridSpec s = column(2, 100);
    KesslerOptions o;
    o.evaporation = false;
    for (double dt : {10.0, 1e3, 1e5, 1e9}) {
        Column c(2);
        std::fill(c.qc.begin(), c.qc.end(), 5e-3f);
        std::fill(c.qr.begin(), c.qr.end(), 1e-4f);
        kessler_conversions(s, c.theta, c.qv, c.qc, c.qr, c.p, c.pi, c.rho, dt, o);
        for (size_t n = 0; n < c.qc.size(); ++n) {
            ASSERT_TRUE(std::isfinite(c.qc[n]) && std::isfinite(c.qr[n]));
            EXPECT_GE(c.qc[n], 0.f);
            EXPECT_LE(c.qc[n], 5e-3f);
            EXPECT_GE(c.qr[n], 1e-4f);
            EXPECT_NEAR(double(c.qc[n]) + c.qr[n], 5.1e-3, 1e-9) << dt;
        }
    }
}

// Rain evaporates in subsaturated air, cools it, and never pushes it past
// saturation even at dt = 1e6 s; saturated air does not evaporate rain.
TEST(SimKessler, EvaporationBoundedBySaturation) {
    GridSpec s = column(2, 100);
    KesslerOptions o;
    for (double dt : {1.0, 100.0, 1e6}) {
        Column c(2);
        std::fill(c.qr.begin(), c.qr.end(), 1e-3f);
        std::fill(c.qv.begin(), c.qv.end(), 5e-3f);
        KesslerReport r = kessler_conversions(s, c.theta, c.qv, c.qc, c.qr, c.p, c.pi, c.rho, dt, o);
        EXPECT_GT(r.evaporated, 0);
        for (size_t n = 0; n < c.qr.size(); ++n) {
            size_t k = n / 2;
            double qs = saturation_mixing_ratio(c.theta[n] * c.pi[k], c.p[k]);
            EXPECT_GE(c.qr[n], 0.f);
            EXPECT_LE(c.qv[n], qs * (1 + 1e-3)) << dt;
            EXPECT_LT(c.theta[n], 300.f);
            EXPECT_NEAR(double(c.qv[n]) + c.qr[n], 6e-3, 1e-9);
        }
    }
    {
        Column c(2);
        c.qr[1] = std::nanf("");
        try {
            kessler_conversions(s, c.theta, c.qv, c.qc, c.qr, c.p, c.pi, c.rho, 1.0, o);
            FAIL() << "NaN accepted";
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find("qr"), std::string::npos) << e.what();
        }
        EXPECT_THROW(rain_sedimentation(s, c.qr, c.rho, 1.0, o), Error);
        EXPECT_THROW(kessler_conversions(s, c.theta, c.qv, c.qc, c.qr, c.p, c.pi, c.rho, -1.0, o), Error);
    }
    Column c(2);
    for (size_t n = 0; n < c.qv.size(); ++n) c.qv[n] = float(1.01 * saturation_mixing_ratio(300 * c.pi[n / 2], c.p[n / 2]));
    std::fill(c.qr.begin(), c.qr.end(), 1e-3f);
    EXPECT_EQ(kessler_conversions(s, c.theta, c.qv, c.qc, c.qr, c.p, c.pi, c.rho, 100, o).evaporated, 0.0);
}

// Sedimentation: a rain layer aloft in an anelastic column falls out; the
// water mass sum(rho qr dz dx^2) + fallout is conserved to float precision
// (1e-6 relative) at any dt; qr stays >= 0; the fall speed follows
// 36.34 (rho qr)^0.1364 sqrt(rho_s / rho) (grows with qr and with height).
TEST(SimKessler, SedimentationConservesWaterPlusFallout) {
    const int nz = 40;
    GridSpec s = column(nz, 100);
    Column c(nz);
    EXPECT_GT(rain_fall_speed(2e-3, 1.0, 1.0), rain_fall_speed(1e-3, 1.0, 1.0));
    EXPECT_NEAR(rain_fall_speed(2e-3, 0.5, 1.0) / rain_fall_speed(1e-3, 1.0, 1.0), std::sqrt(2.0), 1e-12); // same rho qr
    EXPECT_EQ(rain_fall_speed(0, 1, 1), 0.0);
    for (int k = 25; k < 35; ++k) c.qr[size_t(2 * k)] = c.qr[size_t(2 * k + 1)] = 2e-3f;
    auto mass = [&]() {
        double m = 0;
        for (int k = 0; k < nz; ++k) m += c.rho[size_t(k)] * (double(c.qr[size_t(2 * k)]) + c.qr[size_t(2 * k + 1)]) * 100 * 100 * 100;
        return m;
    };
    const double m0 = mass();
    double out = 0;
    KesslerOptions o;
    for (double dt : {7.0, 60.0, 600.0, 3000.0}) {
        KesslerReport r = rain_sedimentation(s, c.qr, c.rho, dt, o);
        out += r.fallout;
        for (float q : c.qr) ASSERT_GE(q, 0.f);
        EXPECT_GE(r.sedimentation_substeps, 1);
        std::printf("[sim] sedimentation dt %g: %d substeps, fallout %.6g kg, mass %.6g kg\n", dt, r.sedimentation_substeps,
                    out, mass());
        EXPECT_NEAR(mass() + out, m0, 1e-6 * m0);
    }
    EXPECT_GT(out, 0.9 * m0); // after ~1 h nearly all rain has reached the floor
}

// In the Simulation: off by default (no qr); on, a saturated cloudy
// atmosphere rains: qr >= 0, fallout > 0, the report carries the budget and
// water mass + cumulative fallout stays within the advection's own drift.
TEST(SimKessler, SimulationRainsOutOfASaturatedCloud) {
    GridSpec s;
    s.nx = 16;
    s.ny = 1;
    s.nz = 24;
    s.dx = 100;
    Sounding snd;
    snd.surface_theta = 280;
    snd.total_water = 0.012;
    Simulation dry(s, snd, {});
    EXPECT_TRUE(dry.qr().empty());
    SimOptions o;
    o.rain = true;
    Simulation sim(s, snd, o);
    ASSERT_EQ(sim.qr().size(), s.cells());
    StepReport r0 = sim.step(1.0);
    double m0 = r0.water_mass + r0.rain_fallout, fallout = r0.rain_fallout;
    StepReport r;
    for (int n = 0; n < 30; ++n) {
        r = sim.step(20.0);
        fallout += r.rain_fallout;
        for (float q : sim.qr()) ASSERT_GE(q, 0.f);
        ASSERT_TRUE(std::isfinite(r.max_w));
    }
    std::printf("[sim] rain column: max qr %.3g, fallout %.4g kg, water mass %.6g kg (start %.6g)\n", r.max_qr, fallout,
                r.water_mass, m0);
    EXPECT_GT(r.max_qr, 0);
    EXPECT_GT(fallout, 0);
    EXPECT_GT(r.autoconverted + r.accreted, 0);
    // horizontally uniform: advection is exact, so the budget closes to float rounding
    EXPECT_NEAR(r.water_mass + fallout, m0, 1e-5 * m0);
    EXPECT_NE(r.to_json().find("\"rain_fallout\""), std::string::npos);
    SimOptions bad = o;
    bad.moist = false;
    EXPECT_THROW(Simulation(s, snd, bad), Error);
    bad = o;
    bad.kessler.autoconversion_rate = -1;
    EXPECT_THROW(Simulation(s, snd, bad), Error);
}

// Rain and the reversible thermodynamics keep the solver bit-identical across
// thread counts (1 and 2 TBB threads, 3D grid, rain falling through a cloud).
TEST(SimKessler, RainAndReversibleBitIdenticalAcrossThreadCounts) {
    GridSpec s;
    s.nx = s.ny = 12;
    s.nz = 16;
    s.dx = 100;
    Sounding snd;
    snd.theta_e = 320;
    snd.total_water = 0.015;
    SimOptions o;
    o.rain = true;
    o.reversible_theta_e = true;
    auto run = [&](int threads) {
        tbb::task_arena arena(threads);
        std::vector<float> out;
        arena.execute([&] {
            Simulation sim(s, snd, o);
            std::vector<float> d(s.cells(), 0.f);
            for (int k = 2; k < 6; ++k)
                for (int j = 4; j < 8; ++j)
                    for (int i = 3; i < 8; ++i) d[(size_t(k) * s.ny + j) * s.nx + i] = 1.f;
            sim.add_theta(d);
            for (int n = 0; n < 4; ++n) sim.step(20.0);
            out = sim.theta();
            out.insert(out.end(), sim.qr().begin(), sim.qr().end());
            out.insert(out.end(), sim.velocity().w.begin(), sim.velocity().w.end());
        });
        return out;
    };
    std::vector<float> a = run(1), b = run(2);
    ASSERT_EQ(a.size(), b.size());
    EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(float)), 0);
}

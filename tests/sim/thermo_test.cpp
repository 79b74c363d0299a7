#include "atlas/sim/thermo.h"

#include "atlas/core/error.h"

#include <gtest/gtest.h>

#include <cmath>

using namespace atlas;
using namespace atlas::sim;

TEST(SimThermo, BoltonAgainstTabulatedValues) {
    // WMO tables: e_s(0 C) = 611.2 Pa, e_s(20 C) = 2339 Pa, e_s(30 C) = 4246 Pa (within 0.5 %).
    EXPECT_NEAR(saturation_vapor_pressure(273.15), 611.2, 0.1);
    EXPECT_NEAR(saturation_vapor_pressure(293.15), 2339, 12);
    EXPECT_NEAR(saturation_vapor_pressure(303.15), 4246, 21);
    EXPECT_TRUE(std::isfinite(saturation_mixing_ratio(500, 1000)));
}

// Stiff condensation: relax = 1 - exp(-rate dt) for rate x dt in 0.1 .. 10, and
// extreme supersaturation (qv 10x saturation). Tolerances: water to 1e-15
// absolute (double arithmetic), saturation to 1e-9 relative after convergence.
TEST(SimThermo, StiffCondensationBoundedConservedConverges) {
    const double p = 85000, pi = exner(p);
    for (double rdt : {0.1, 0.5, 1.0, 3.0, 10.0}) {
        for (double super : {1.01, 2.0, 10.0}) {
            double theta = 290, T = theta * pi;
            double qv = super * saturation_mixing_ratio(T, p), qc = 0;
            const double qt = qv + qc, thl = theta - kLv / (kCp * pi) * qc;
            double relax = 1 - std::exp(-rdt);
            for (int step = 0; step < 200; ++step) {
                AdjustResult r = saturation_adjust(theta, qv, qc, p, relax);
                ASSERT_GE(r.qv, 0);
                ASSERT_GE(r.qc, 0);
                ASSERT_TRUE(std::isfinite(r.theta));
                // Between the old state and equilibrium: no overshoot.
                ASSERT_LE(r.qc, qt + 1e-15);
                theta = r.theta, qv = r.qv, qc = r.qc;
                EXPECT_NEAR(qv + qc, qt, 1e-15);
                EXPECT_NEAR(theta - kLv / (kCp * pi) * qc, thl, 1e-9);
            }
            double qs = saturation_mixing_ratio(theta * pi, p);
            EXPECT_NEAR(qv / qs, 1.0, 1e-6) << rdt << " " << super;
            EXPECT_GT(qc, 0);
        }
    }
}

TEST(SimThermo, DryStaysDrySubsaturatedEvaporates) {
    AdjustResult dry = saturation_adjust(300, 0, 0, 1e5);
    EXPECT_EQ(dry.qc, 0);
    EXPECT_EQ(dry.theta, 300);
    // Cloud in sub-saturated air evaporates completely and cools.
    AdjustResult ev = saturation_adjust(300, 0.001, 0.002, 1e5);
    EXPECT_EQ(ev.qc, 0);
    EXPECT_NEAR(ev.qv, 0.003, 1e-15);
    EXPECT_LT(ev.theta, 300);
    // Exactly saturated: nothing changes (to 1e-9 kg/kg).
    double qs = saturation_mixing_ratio(300 * exner(9e4), 9e4);
    AdjustResult sat = saturation_adjust(300, qs, 0, 9e4);
    EXPECT_NEAR(sat.qc, 0, 1e-9);
}

TEST(SimThermo, RejectsNonFinite) {
    EXPECT_THROW(saturation_adjust(std::nan(""), 0, 0, 1e5), Error);
    EXPECT_THROW(saturation_adjust(300, INFINITY, 0, 1e5), Error);
    EXPECT_THROW(saturation_adjust(300, 0, 0, 0), Error);
}

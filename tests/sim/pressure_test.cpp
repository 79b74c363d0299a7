#include "atlas/sim/pressure.h"

#include "atlas/core/error.h"
#include "atlas/core/hash.h"

#include "random_velocity.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

using namespace atlas;
using namespace atlas::sim;

namespace {
using test::random_velocity;
GridSpec cube(int n, BoundarySet b) {
    GridSpec s;
    s.nx = s.ny = s.nz = n;
    s.dx = 1.0;
    s.boundary = b;
    return s;
}
} // namespace

// Tolerance: relative residual 1e-6 -> max |div| * dx / max|u| below 1e-4
// (float storage of the corrected velocity limits it near 1e-6).
TEST(SimPressure, RandomFieldClosedBoxBecomesDivergenceFree) {
    GridSpec s = cube(24, all_closed());
    PressureSolver solver(s);
    MacVelocity v = random_velocity(s, 7);
    ProjectionReport r = solver.project(v, {});
    EXPECT_TRUE(r.converged);
    EXPECT_GT(r.before.max, 0.5);
    EXPECT_LT(r.after.max, 1e-4);
    EXPECT_LT(r.after.l2, 1e-5);
    // Walls stay shut and a second projection changes (almost) nothing: no drift from the null space.
    for (int k = 0; k < s.nz; ++k)
        for (int j = 0; j < s.ny; ++j) EXPECT_EQ(v.u[v.iu(0, j, k)], 0.f);
    MacVelocity v2 = v;
    ProjectionReport r2 = solver.project(v2, {});
    double dmax = 0;
    for (size_t n = 0; n < v.u.size(); ++n) dmax = std::max(dmax, double(std::fabs(v.u[n] - v2.u[n])));
    EXPECT_LT(dmax, 1e-4);
    EXPECT_LT(r2.after.max, 1e-4);
}

TEST(SimPressure, RandomFieldOpenAndMixedBoxes) {
    BoundarySet mixed = all_closed();
    mixed[5] = Boundary::Open; // open top
    mixed[1] = Boundary::Open;
    for (BoundarySet b : {all_open(), mixed}) {
        GridSpec s = cube(20, b);
        PressureSolver solver(s);
        MacVelocity v = random_velocity(s, 11);
        ProjectionReport r = solver.project(v, {});
        EXPECT_TRUE(r.converged);
        EXPECT_LT(r.after.max, 1e-4);
    }
}

TEST(SimPressure, SlabAndAnelasticDensity) {
    GridSpec s;
    s.nx = 64;
    s.ny = 1;
    s.nz = 32;
    s.dx = 100;
    std::vector<double> rho(32);
    for (int k = 0; k < 32; ++k) rho[size_t(k)] = 1.2 * std::exp(-(k + 0.5) * 100 / 8000.0);
    PressureSolver solver(s, rho);
    MacVelocity v = random_velocity(s, 3);
    ProjectionReport r = solver.project(v, {});
    EXPECT_TRUE(r.converged);
    EXPECT_LT(r.after.max * s.dx, 1e-4);
    for (float x : v.v) EXPECT_EQ(x, 0.f);
}

// Multigrid keeps the CG iteration count bounded as the grid grows; Jacobi-PCG does not.
TEST(SimPressure, IterationsBoundedFrom16To64) {
    int it16 = 0, it64 = 0;
    for (int n : {16, 32, 64}) {
        GridSpec s = cube(n, all_closed());
        PressureSolver solver(s);
        MacVelocity v = random_velocity(s, 5);
        ProjectionReport r = solver.project(v, {});
        EXPECT_TRUE(r.converged) << n;
        RecordProperty("iterations_" + std::to_string(n), r.iterations);
        std::printf("[sim] %d^3 closed: %d MG-PCG iterations, div max %.3g\n", n, r.iterations, r.after.max);
        EXPECT_LT(r.after.max, 1e-4) << n;
        if (n == 16) it16 = r.iterations;
        if (n == 64) it64 = r.iterations;
    }
    EXPECT_LE(it64, 12);
    EXPECT_LE(it64, it16 + 3) << it16 << " " << it64;
}

TEST(SimPressure, RejectsNaNAndMismatch) {
    GridSpec s = cube(8, all_closed());
    PressureSolver solver(s);
    MacVelocity v(s);
    v.u[5] = std::nanf("");
    EXPECT_THROW(solver.project(v, {}), Error);
    MacVelocity other(cube(9, all_closed()));
    EXPECT_THROW(solver.project(other, {}), Error);
    GridSpec bad = s;
    bad.dx = -1;
    EXPECT_THROW(PressureSolver{bad}, Error);
}

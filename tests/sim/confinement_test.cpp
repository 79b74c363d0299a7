// Vorticity confinement: the force against the formula on an analytic vortex,
// and its effect on a rising bubble at cumulus cell sizes.
#include "atlas/sim/confinement.h"
#include "atlas/sim/simulation.h"
#include "atlas/core/error.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

using namespace atlas::sim;

namespace {
// Max w of a dry warm bubble (2 K, radius 300 m) in a neutral 1.5 km cube after `seconds`.
double bubble_max_w(int n, double eps, double seconds) {
    GridSpec s;
    s.nx = s.ny = s.nz = n;
    s.dx = 1500.0 / n;
    s.boundary[5] = Boundary::Open;
    Sounding snd;
    snd.surface_theta = 300;
    SimOptions o;
    o.moist = false;
    o.cfl = 2;
    o.vorticity_confinement = eps;
    Simulation sim(s, snd, o);
    std::vector<float> d(s.cells(), 0.f);
    for (int k = 0; k < n; ++k)
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i) {
                double x = (i + 0.5) * s.dx - 750, y = (j + 0.5) * s.dx - 750, z = (k + 0.5) * s.dx - 350;
                double r = std::sqrt(x * x + y * y + z * z) / 300;
                if (r < 1) d[sim.velocity().ic(i, j, k)] = float(2.0 * std::pow(std::cos(0.5 * M_PI * r), 2));
            }
    sim.add_theta(d);
    double mw = 0;
    for (double t = 0; t < seconds; t += 20) mw = std::max(mw, sim.step(20).max_w);
    return mw;
}

// Face velocities of a Lamb-Oseen vortex about the z axis through (cx, cy):
// u_theta = G / (2 pi r) (1 - exp(-r^2/a^2)), omega_z = G / (pi a^2) exp(-r^2/a^2).
MacVelocity lamb_oseen(int n, double dx, double G, double a) {
    GridSpec s;
    s.nx = s.ny = n;
    s.nz = 4;
    s.dx = dx;
    MacVelocity v(s);
    const double c = 0.5 * n * dx;
    auto ut = [&](double x, double y, double& u, double& w) {
        double r2 = (x - c) * (x - c) + (y - c) * (y - c);
        double k = r2 > 0 ? G / (2 * M_PI * r2) * (1 - std::exp(-r2 / (a * a))) : 0;
        u = -k * (y - c), w = k * (x - c);
    };
    for (int k = 0; k < s.nz; ++k)
        for (int j = 0; j < n; ++j)
            for (int i = 0; i <= n; ++i) {
                double uu, vv;
                ut(i * dx, (j + 0.5) * dx, uu, vv);
                v.u[v.iu(i, j, k)] = float(uu);
            }
    for (int k = 0; k < s.nz; ++k)
        for (int j = 0; j <= n; ++j)
            for (int i = 0; i < n; ++i) {
                double uu, vv;
                ut((i + 0.5) * dx, j * dx, uu, vv);
                v.v[v.iv(i, j, k)] = float(vv);
            }
    return v;
}
} // namespace

// The force on a Lamb-Oseen vortex equals eps dx |omega| (N x omega) from the
// analytic omega: N = -r_hat, so f = eps dx omega^2 along the flow (theta_hat).
TEST(SimConfinement, ForceMatchesFormulaOnLambOseenVortex) {
    const int n = 96;
    const double dx = 10, a = 150, G = M_PI * a * a * 0.1, eps = 0.2; // peak omega 0.1 1/s
    MacVelocity v = lamb_oseen(n, dx, G, a);
    std::vector<float> fx, fy, fz;
    confinement_force(v, eps, fx, fy, fz);
    const double c = 0.5 * n * dx;
    double worst = 0;
    int checked = 0;
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            double x = (i + 0.5) * dx - c, y = (j + 0.5) * dx - c, r = std::hypot(x, y);
            size_t cell = v.ic(i, j, 1);
            ASSERT_EQ(fz[cell], 0.f);
            if (r < 0.5 * a || r > 2 * a) continue;
            double om = G / (M_PI * a * a) * std::exp(-r * r / (a * a));
            double mag = eps * dx * om * om;
            double ex = -mag * y / r, ey = mag * x / r; // theta_hat
            double err = std::hypot(fx[cell] - ex, fy[cell] - ey) / mag;
            worst = std::max(worst, err);
            ++checked;
        }
    EXPECT_GT(checked, 500);
    EXPECT_LT(worst, 0.05) << "relative error of the force against the formula";
}

// The same vortex in millimetre and 100 km cells (velocities scaled with the
// size, so omega is the same): the same relative force, finite, no guard misfire.
TEST(SimConfinement, ForceIsScaleFreeAtExtremeCellSizes) {
    for (double scale : {1e-4, 1e4}) {
        const int n = 48;
        const double dx = 10 * scale, a = 100 * scale, G = M_PI * a * a * 0.1;
        MacVelocity ref = lamb_oseen(n, 10, G / (scale * scale), 100), v = lamb_oseen(n, dx, G, a);
        std::vector<float> rx, ry, rz, fx, fy, fz;
        confinement_force(ref, 0.2, rx, ry, rz);
        confinement_force(v, 0.2, fx, fy, fz);
        double peak = 0;
        for (float f : rx) peak = std::max(peak, double(std::fabs(f)));
        ASSERT_GT(peak, 0);
        for (size_t c = 0; c < fx.size(); ++c) {
            ASSERT_TRUE(std::isfinite(fx[c]) && std::isfinite(fy[c]));
            ASSERT_NEAR(fx[c] / scale, rx[c], 1e-3 * peak) << scale << " cell " << c;
            ASSERT_NEAR(fy[c] / scale, ry[c], 1e-3 * peak) << scale << " cell " << c;
        }
    }
}

// Linear in eps and in dx for the same physical vortex (the force vanishes under refinement).
TEST(SimConfinement, ForceScalesWithEpsAndCellSize) {
    const double a = 150, G = M_PI * a * a * 0.1;
    MacVelocity fine = lamb_oseen(96, 10, G, a), coarse = lamb_oseen(48, 20, G, a);
    std::vector<float> f1x, f1y, f1z, f2x, f2y, f2z, f3x, f3y, f3z;
    confinement_force(fine, 0.1, f1x, f1y, f1z);
    confinement_force(fine, 0.3, f3x, f3y, f3z);
    confinement_force(coarse, 0.1, f2x, f2y, f2z);
    // Cell (i, j) of the coarse grid at radius ~a: centre (2i+1) fine-cell edges = fine cells 2i, 2i+1.
    int ic = 24 + 7, jc = 24;                       // coarse cell ~150 m right of the centre
    double coarse_f = std::hypot(f2x[coarse.ic(ic, jc, 1)], f2y[coarse.ic(ic, jc, 1)]);
    double fine_f = 0, fine_f3 = 0;
    for (int dj = 0; dj < 2; ++dj)
        for (int di = 0; di < 2; ++di) {
            size_t c = fine.ic(2 * ic + di, 2 * jc + dj, 1);
            fine_f += 0.25 * std::hypot(f1x[c], f1y[c]);
            fine_f3 += 0.25 * std::hypot(f3x[c], f3y[c]);
        }
    EXPECT_NEAR(fine_f3 / fine_f, 3.0, 1e-4);
    EXPECT_NEAR(coarse_f / fine_f, 2.0, 0.2);
}

// Uniform vorticity (solid-body rotation) has no vortex edge: grad|omega| is
// round-off, N must not be normalised out of it.
TEST(SimConfinement, NoForceInSolidBodyRotationOrAtRest) {
    GridSpec s;
    s.nx = s.ny = 32;
    s.nz = 3;
    s.dx = 25;
    MacVelocity v(s), rest(s);
    const double Om = 0.0537, c = 16.37 * s.dx; // off-node axis: omega is flat only up to float round-off
    for (int k = 0; k < s.nz; ++k) {
        for (int j = 0; j < s.ny; ++j)
            for (int i = 0; i <= s.nx; ++i) v.u[v.iu(i, j, k)] = float(-Om * ((j + 0.5) * s.dx - c));
        for (int j = 0; j <= s.ny; ++j)
            for (int i = 0; i < s.nx; ++i) v.v[v.iv(i, j, k)] = float(Om * ((i + 0.5) * s.dx - c));
    }
    std::vector<float> fx, fy, fz;
    confinement_force(v, 2.0, fx, fy, fz);
    double worst = 0;
    for (size_t n = 0; n < fx.size(); ++n) worst = std::max({worst, double(std::fabs(fx[n])), double(std::fabs(fy[n]))});
    EXPECT_LT(worst, 1e-6 * 2.0 * s.dx * 4 * Om * Om) << "force from round-off of a flat |omega|";
    confinement_force(rest, 2.0, fx, fy, fz);
    for (size_t n = 0; n < fx.size(); ++n) ASSERT_EQ(fx[n] + fy[n] + fz[n], 0.f);
}

// The cumulus graph's failure: eps 0.15 at 47..94 m cells drove updrafts far
// past the eps = 0 run. Now confinement adds detail, not energy.
TEST(SimConfinement, BubbleUpdraftStaysNearTheUnconfinedRun) {
    for (int n : {16, 32}) {
        double w0 = bubble_max_w(n, 0.0, 400), w1 = bubble_max_w(n, 0.1, 400);
        EXPECT_GT(w0, 2.0) << n;
        EXPECT_LT(w1, 1.5 * w0) << n;
        EXPECT_GE(w1, w0 * 0.9) << n;
    }
}

// Same physical bubble at 94 m and 47 m cells: similar max w with confinement.
TEST(SimConfinement, BubbleUpdraftSimilarAtTwoResolutions) {
    double coarse = bubble_max_w(16, 0.1, 400), fine = bubble_max_w(32, 0.1, 400);
    EXPECT_LT(std::fabs(fine - coarse) / fine, 0.25) << coarse << " vs " << fine;
}

// The largest allowed eps (0.2) stays finite and bounded; beyond it the
// confinement outgrows the advection's dissipation and is refused.
TEST(SimConfinement, LargestEpsStaysBoundedAndLargerIsRefused) {
    double w0 = bubble_max_w(32, 0.0, 400), w2 = bubble_max_w(32, 0.2, 400);
    EXPECT_TRUE(std::isfinite(w2));
    EXPECT_LT(w2, 4 * w0);
    SimOptions o;
    o.vorticity_confinement = 0.21;
    EXPECT_THROW(o.validate(4), atlas::Error);
}

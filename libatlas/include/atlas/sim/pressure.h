// atlas/sim/pressure.h - pressure projection: makes a MAC velocity divergence-free.
//
// Solves div(rho0 grad phi) = div(rho0 u) by conjugate gradients preconditioned
// with one symmetric multigrid V-cycle (Galerkin aggregation coarse grids, coarse
// correction over-corrected by 1.8,
// red-black Gauss-Seidel smoothing, a dense Cholesky solve on the coarsest
// grid), then sets u -= grad phi. rho0(z) is the anelastic reference density
// (all ones = Boussinesq). Closed faces are Neumann, open faces Dirichlet
// (ambient pressure), periodic x/y faces couple the first and last cells. In a
// box with no open face (closed and periodic) the operator is singular: the
// right-hand side is made to sum to zero and the mean of phi is removed in
// every iteration, so the null space cannot drift.
// Convergence: ||r||_2 <= tolerance * ||b||_2 (relative to the right-hand side,
// the same test at every grid size). Arithmetic in double; reductions run over
// fixed z-slices in a fixed order, so results are bit-identical for any
// thread count. A PressureSolver is not thread-safe (it owns scratch); use one
// per simulation.
#pragma once

#include "atlas/sim/mac_grid.h"

#include <memory>
#include <vector>

namespace atlas::sim {

// Bounds and docs: the pressure_* options of sim::sim_options() (sim_options.h),
// which PressureSolver::project checks.
struct ProjectionOptions {
    double tolerance = 1e-6;  // relative residual
    int max_iterations = 200; // CG iterations
    bool multigrid = true;    // false: Jacobi-preconditioned CG (for comparison)
};

struct ProjectionReport {
    int iterations = 0;
    double relative_residual = 0; // ||r|| / ||b|| reached
    bool converged = false;
    DivergenceStats before, after; // 1/s
    int levels = 0;                // multigrid levels used
};

class PressureSolver {
public:
    // rho_cell: nz reference densities at cell centres (kg/m^3, > 0), or empty
    // for Boussinesq; rho_face is derived (mean of the neighbours, edge values
    // copied). Throws atlas::Error on a bad spec or density; checks `budget`.
    PressureSolver(const GridSpec& spec, std::vector<double> rho_cell = {}, const MemoryBudget* budget = nullptr);
    ~PressureSolver();
    PressureSolver(PressureSolver&&) noexcept;
    PressureSolver& operator=(PressureSolver&&) noexcept;

    // Projects `vel` (same spec) in place. Throws atlas::Error when the input
    // holds NaN/Inf or does not match the spec. Not converging within
    // max_iterations is reported (converged = false), not thrown.
    ProjectionReport project(MacVelocity& vel, const ProjectionOptions& options);

    const std::vector<double>& rho_cell() const { return rho_cell_; }
    const std::vector<double>& rho_face() const { return rho_face_; }

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
    std::vector<double> rho_cell_, rho_face_;
};

} // namespace atlas::sim

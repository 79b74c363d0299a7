// atlas/sim/mac_grid.h - the staggered (MAC) grid the cloud solver works on.
//
// Cells are cubes of edge `dx` metres; z is up (gravity along -z). A 2D run is
// a one-cell slab: ny == 1 (x-z plane) or nx == 1. Scalars (theta', qv, qc, qr)
// sit at cell centres; velocity components sit on the faces normal to them:
// u at (i, j+1/2, k+1/2) with i in [0, nx], v at j in [0, ny], w at k in [0, nz].
// Storage is x fastest, then y, then z, like Field3D.
// A MacGrid is a plain value; reading it from many threads is safe.
#pragma once

#include "atlas/core/memory.h"

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace atlas::sim {

// What happens at one face of the domain.
//   Closed: a free-slip wall; normal velocity 0, pressure gradient 0 (Neumann).
//   Open:   an outflow/inflow face held at ambient pressure (Dirichlet p' = 0);
//           the normal velocity there is whatever the projection makes it.
//   Periodic: the face is glued to the opposite one (x- to x+, y- to y+): what
//           leaves through one enters through the other. Both faces of the pair
//           must be periodic, only x and y can be (z carries gravity), and the
//           axis needs an even number of cells (>= 2; the red-black smoother of
//           the pressure solver). On a periodic axis the face arrays keep their
//           n + 1 entries and face n is a copy of face 0 (enforce_walls).
enum class Boundary { Closed, Open, Periodic };

// Faces in the order x-, x+, y-, y+, z-, z+.
using BoundarySet = std::array<Boundary, 6>;
constexpr BoundarySet all_closed() { return {Boundary::Closed, Boundary::Closed, Boundary::Closed, Boundary::Closed, Boundary::Closed, Boundary::Closed}; }
constexpr BoundarySet all_open() { return {Boundary::Open, Boundary::Open, Boundary::Open, Boundary::Open, Boundary::Open, Boundary::Open}; }

// Size and spacing of a simulation grid.
//   nx, ny, nz: cells, each in [1, 4096], at least 2 along two axes.
//   dx: cell edge in metres, in [1e-3, 1e5] (what the grid, the advection and
//       the pressure solver accept). A Simulation also needs its top cell centre,
//       (nz - 1/2) dx, inside the modelled atmosphere (Exner > 0.05: about 29 km
//       for a neutral 300 K sounding, so dx <= 19.5 km at nz = 2 and 58 km for an
//       x-y slab with nz = 1); make_reference refuses it naming that height.
// A direction with a single cell is always treated as closed (a 2D slab).
struct GridSpec {
    int nx = 0, ny = 0, nz = 0;
    double dx = 1.0;
    BoundarySet boundary = all_closed();

    size_t cells() const { return size_t(nx) * size_t(ny) * size_t(nz); }
    // Throws atlas::Error naming the bad member when the spec is out of range.
    void validate() const;
    // The boundary actually used: single-cell directions are forced closed.
    Boundary face(int f) const;
    // True when axis a (0 = x, 1 = y) wraps around (both faces Periodic, > 1 cell).
    bool periodic(int a) const { return a < 2 && face(2 * a) == Boundary::Periodic; }
};

// Bytes per cell of a whole Simulation (state, advection scratch, pressure
// solver with its multigrid hierarchy); the estimate used before allocating.
// 4-byte floats: state u, v, w, theta, qv, qc (6), velocity scratch (3),
// scalar scratch (3), sources (2), shared back-traces (6), MacCormack back
// value (1), vorticity-confinement scratch (10, only when enabled): 31 floats
// = 124 B. Pressure solver in double: diag, x, b, r, phi, res, z, d, q, rhs
// (10 doubles = 80 B) plus about 1/7 of 7 doubles for coarse levels (8 B).
// Total 212 B, rounded up to 216 B per cell. Options add to it (simulation.h:
// kSimRainBytesPerCell, kSimReflectionBytesPerCell; simulation_bytes(spec, options)).
constexpr uint64_t kSimBytesPerCell = 216;
uint64_t simulation_bytes(const GridSpec& spec);

// Velocity on a MAC grid, in m/s.
struct MacVelocity {
    GridSpec spec;
    std::vector<float> u, v, w;

    MacVelocity() = default;
    // Zero velocity. Validates `spec`; checks `budget` (3 face arrays) when given.
    explicit MacVelocity(const GridSpec& spec, const MemoryBudget* budget = nullptr);

    size_t iu(int i, int j, int k) const { return (size_t(k) * size_t(spec.ny) + size_t(j)) * size_t(spec.nx + 1) + size_t(i); }
    size_t iv(int i, int j, int k) const { return (size_t(k) * size_t(spec.ny + 1) + size_t(j)) * size_t(spec.nx) + size_t(i); }
    size_t iw(int i, int j, int k) const { return (size_t(k) * size_t(spec.ny) + size_t(j)) * size_t(spec.nx) + size_t(i); }
    size_t ic(int i, int j, int k) const { return (size_t(k) * size_t(spec.ny) + size_t(j)) * size_t(spec.nx) + size_t(i); }

    // Sets the normal velocity on closed faces (and in single-cell directions) to 0;
    // on a periodic axis copies face 0 onto face n (the same face).
    void enforce_walls();
    // Largest |component| in m/s (NaN if any component is NaN).
    double max_abs() const;
};

// Divergence statistics over all cells, in 1/s: root-mean-square and max |div u|.
// `face_weight_z(k)`-free form: plain (Boussinesq) divergence.
struct DivergenceStats {
    double l2 = 0;  // sqrt(mean of div^2)
    double max = 0; // max |div|
};
DivergenceStats divergence_stats(const MacVelocity& vel);

// The same with the anelastic weight: div(rho0 u) / rho0(cell), where rho_cell
// has nz entries (cell centres) and rho_face nz + 1 (w faces).
DivergenceStats divergence_stats(const MacVelocity& vel, const std::vector<double>& rho_cell,
                                 const std::vector<double>& rho_face);

} // namespace atlas::sim

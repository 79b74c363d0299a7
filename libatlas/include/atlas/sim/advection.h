// atlas/sim/advection.h - transport of scalars and velocity on the MAC grid.
//
// Semi-Lagrangian: each sample is traced back through the velocity field
// (second-order midpoint rule) and the old field is read there trilinearly.
// MacCormack (Selle et al. 2008): a forward and a backward semi-Lagrangian
// step estimate the error, half of which is removed; the result is clamped
// to the min/max of the source cells the forward step read (so it can never
// create new extrema), and samples whose trace ends within one cell of an open
// face keep the plain semi-Lagrangian value.
// Back-traces are clamped into the domain (walls and open faces alike read
// the edge value: zero-gradient inflow); along a periodic axis they wrap
// around instead, and the reads too. Traces along a periodic axis are made
// relative to their lattice node, so shifting every field by whole cells along
// it shifts the result by the same cells, bit for bit. Deterministic for any
// thread count.
#pragma once

#include "atlas/sim/mac_grid.h"

#include <span>
#include <vector>

namespace atlas::sim {

// SemiLagrangian: trilinear read at the back-traced point (first-order, most
// diffusive). MacCormack: limited forward/backward error correction (above).
// CubicLimited: the read is a Catmull-Rom (tricubic, 4 samples per axis,
// clamped indices at the edges) interpolation clamped to the min/max of the 8
// surrounding samples, so it creates no new extrema; third-order
// interpolation, much less smearing of thin filaments at one read per step.
enum class AdvectionScheme { SemiLagrangian, MacCormack, CubicLimited };

// A staggered sample lattice: n[] samples per axis, sample (i,j,k) at
// ((i + offset[0]) dx, ...). Cell centres: n = (nx,ny,nz), offset 0.5.
// period[a] > 0: axis a wraps with that many samples (the grid's cell count;
// a face lattice along it has period + 1 samples, the last a copy of the
// first). The *_lattice(spec) makers set it from the spec's periodic axes.
struct Lattice {
    int n[3];
    double offset[3];
    int period[3] = {0, 0, 0};
    size_t size() const { return size_t(n[0]) * n[1] * n[2]; }
};
Lattice cell_lattice(const GridSpec& s);
Lattice u_lattice(const GridSpec& s);
Lattice v_lattice(const GridSpec& s);
Lattice w_lattice(const GridSpec& s);

// Trilinear value of `q` (on lattice `l`) at position p given in cell units
// (world / dx, from the domain's min corner); clamped at the edges, wrapped
// along periodic axes.
float sample_lattice(const Lattice& l, std::span<const float> q, const double p[3]);

// Velocity in cells per second at position p (cell units).
void velocity_at(const MacVelocity& vel, const double p[3], double out[3]);

// Advects q (on lattice l) by `vel` over dt seconds into `out` (same size,
// distinct from q). Both spans must have l.size() elements (else atlas::Error).
void advect(const MacVelocity& vel, const Lattice& l, std::span<const float> q, std::span<float> out, double dt,
            AdvectionScheme scheme);

// The same for several fields on one lattice: the back-traces are computed
// once and shared (qs[f] -> outs[f]). Transient memory: 24 B per lattice node.
void advect_many(const MacVelocity& vel, const Lattice& l, std::span<const std::span<const float>> qs,
                 std::span<const std::span<float>> outs, double dt, AdvectionScheme scheme);

// Self-advection of velocity; `out` gets the result (walls re-imposed).
void advect_velocity(const MacVelocity& vel, MacVelocity& out, double dt, AdvectionScheme scheme);

// Reusable work buffers for the advection calls below (back-trace offsets and
// the MacCormack forward values, 28 B per lattice node at most); keeping one
// per simulation avoids allocating and zeroing them every step. Not shared
// between threads; results do not depend on its previous contents.
struct AdvectionScratch {
    std::vector<float> forward, backward, value;
};
void advect_many(const MacVelocity& vel, const Lattice& l, std::span<const std::span<const float>> qs,
                 std::span<const std::span<float>> outs, double dt, AdvectionScheme scheme, AdvectionScratch& scratch);
void advect_velocity(const MacVelocity& vel, MacVelocity& out, double dt, AdvectionScheme scheme, AdvectionScratch& scratch);

} // namespace atlas::sim

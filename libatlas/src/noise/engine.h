// Internal: a NoiseSpec prepared for evaluation (one lattice per octave and
// sub-noise, tabulated when small) and the batch evaluator every public
// entry point uses. Batches are arrays of lattice coordinates already wrapped
// into [0, period); the kernels loop over them with no per-sample dispatch.
#pragma once

#include "atlas/noise/noise_spec.h"
#include "lattice.h"

#include <array>
#include <cstddef>
#include <vector>

namespace atlas::noise::detail {

template <int D>
struct Plan {
    NoiseSpec spec;
    IVec<D> period{};                  // base period
    std::vector<Lattice<D>> octaves;   // main kernel (Perlin part of Perlin-Worley)
    std::vector<Lattice<D>> curl;      // Curl kernel: octave o, potential c at [o * potentials + c]
    std::vector<Lattice<D>> pw_worley; // Perlin-Worley's Worley octaves
    std::vector<Lattice<D>> curly;     // Curly-Alligator's curl potentials
    int potentials = D == 3 ? 3 : 1;

    // Lattices of at most max_table_points points are tabulated: worth it
    // when there are more samples than points (fields), not for a few lookups.
    Plan(const NoiseSpec& s, int64_t max_table_points);
};

// Per-thread scratch, reused across batches.
struct Scratch {
    std::vector<float> tmp, acc, comp;
    std::array<std::vector<double>, 3> coords;
};

// Evaluates n samples at base lattice coordinates u[a][i] in [0, period[a]).
// out[c] receives component c (noise_components of them), after the output
// stage except `normalize`.
template <int D>
void evaluate(const Plan<D>& plan, const std::array<const double*, D>& u, size_t n, float* const* out, Scratch& scratch);

} // namespace atlas::noise::detail

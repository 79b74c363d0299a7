// atlas/noise/value_noise.h - tileable value noise (the foundation's simple noise).
//
// Lattice values come from hash_coords(seed, lattice point mod period), so the
// noise tiles exactly with an integer period per axis and is deterministic.
// Output range [0, 1]. Thread-safe, pure.
#pragma once

#include "atlas/core/math.h"

#include <cstdint>
#include <span>

namespace atlas::noise {

// Evaluates value noise with quintic interpolation along one row of samples:
// out[i] = noise(x0 + (first + i) dx, y, z), coordinates in lattice cells (first > 0: a
// window of a longer row, to the last bit).
// period: lattice cells per tile in each axis (>= 1).
void value_noise_row(std::span<float> out, double x0, double dx, double y, double z, Vec3i period, uint32_t seed, int64_t first = 0);

// Single sample (for tests and sparse lookups).
float value_noise(double x, double y, double z, Vec3i period, uint32_t seed);

} // namespace atlas::noise

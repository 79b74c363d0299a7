// Internal: exact squared Euclidean distance from every voxel centre to a set
// of points lying on grid lines ("line seeds": each has integer coordinates on
// two axes and a fractional one on the third).
#pragma once

#include "atlas/core/math.h"

#include <cstddef>
#include <functional>
#include <vector>

namespace atlas::volume::detail {

// seeds(axis, base, n, out): fill `out` with the sorted positions (in voxel
// index units along `axis`, may be fractional, may lie outside [0, n-1]) of
// the seeds on the grid line along `axis` whose first sample has flat index
// `base`. Called concurrently for different lines: must be thread-safe.
using LineSeedFn = std::function<void(int axis, size_t base, int n, std::vector<double>& out)>;

// Squared distances in metres^2 (h = voxel edge per axis); +inf everywhere
// when there is no seed. Deterministic for any thread count.
std::vector<float> squared_distance_to_line_seeds(Vec3i res, Vec3d h, const LineSeedFn& seeds, unsigned long long* seed_count = nullptr);

} // namespace atlas::volume::detail

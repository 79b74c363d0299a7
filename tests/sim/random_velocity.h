// Shared by the sim tests: a MAC velocity with every face value a hashed number in
// [-1, 1) (deterministic; the salt separates the three components).
#pragma once

#include "atlas/core/hash.h"
#include "atlas/sim/mac_grid.h"

#include <cstdint>
#include <vector>

namespace atlas::sim::test {

inline MacVelocity random_velocity(const GridSpec& s, uint32_t seed) {
    MacVelocity v(s);
    auto fill = [&](std::vector<float>& a, uint32_t salt) {
        for (size_t n = 0; n < a.size(); ++n) a[n] = 2.f * hash_to_unit(hash_coords(seed + salt, int32_t(n))) - 1.f;
    };
    fill(v.u, 1);
    fill(v.v, 2);
    fill(v.w, 3);
    return v;
}

} // namespace atlas::sim::test

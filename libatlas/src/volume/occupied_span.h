// Internal: the span of a row that holds anything but +0 (empty space skipped by
// nodes for which +0 stays +0: noise erosion, the transform's resampling).
#pragma once

#include <bit>
#include <cstdint>
#include <utility>

namespace atlas::volume::detail {

// [first, last) of the row's samples whose bits are not +0; first == last when all are +0.
inline std::pair<int, int> occupied_span(const float* row, int n) {
    int a = 0, b = n;
    while (a < b && std::bit_cast<uint32_t>(row[a]) == 0u) ++a;
    while (b > a && std::bit_cast<uint32_t>(row[b - 1]) == 0u) --b;
    return {a, b};
}

} // namespace atlas::volume::detail

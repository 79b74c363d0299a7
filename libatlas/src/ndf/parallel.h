// Private: a per-index loop over fixed 4096-element blocks (deterministic:
// each index is written by exactly one task, whatever the thread count).
#pragma once

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cstddef>

namespace atlas::ndf {
template <typename F>
void for_each_index(size_t n, F&& f) {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 4096), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t i = r.begin(); i != r.end(); ++i) f(i);
    });
}
} // namespace atlas::ndf

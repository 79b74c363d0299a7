// Internal to core: element-range parallelism over fixed blocks.
#pragma once

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstddef>

namespace atlas::detail {

// Runs fn(begin, end) over [0, n) in fixed blocks of `block` elements, in
// parallel when there is more than one block. The split never depends on the
// thread count and each element is written by one task, so element-wise work
// gives the same bytes for any number of threads.
template <typename Fn>
void parallel_blocks(size_t n, size_t block, Fn&& fn) {
    const size_t blocks = (n + block - 1) / block;
    if (blocks <= 1) {
        fn(size_t(0), n);
        return;
    }
    tbb::parallel_for(size_t(0), blocks, [&](size_t b) { fn(b * block, std::min(n, (b + 1) * block)); });
}

} // namespace atlas::detail

// atlas/core/parallel.h: the blocks are fixed whatever the thread count, every index is
// visited exactly once, and block-ordered reductions give the same bits on 1..N threads.
#include "atlas/core/parallel.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <atomic>
#include <cmath>
#include <cstring>
#include <mutex>
#include <set>
#include <utility>
#include <vector>

namespace {

const int kThreadCounts[] = {1, 2, 3, 8};

template <class F>
auto in_arena(int threads, F&& f) {
    tbb::task_arena arena(threads);
    return arena.execute(std::forward<F>(f));
}

// The blocks a serial reading of the contract gives: [b*block, min(n, (b+1)*block)).
std::set<std::pair<size_t, size_t>> expected_blocks(size_t n, size_t block) {
    std::set<std::pair<size_t, size_t>> s;
    for (size_t b = 0; b * block < n; ++b) s.insert({b * block, std::min(n, (b + 1) * block)});
    return s;
}

TEST(Parallel, BlocksAreFixedForAnyThreadCount) {
    for (size_t n : {size_t(0), size_t(1), size_t(63), size_t(64), size_t(65), size_t(1000), size_t(4097)}) {
        for (size_t block : {size_t(1), size_t(7), size_t(64), size_t(4096)}) {
            for (int threads : kThreadCounts) {
                std::mutex m;
                std::set<std::pair<size_t, size_t>> seen;
                size_t calls = 0;
                in_arena(threads, [&] {
                    atlas::parallel_blocks(n, block, [&](size_t b, size_t e) {
                        std::lock_guard<std::mutex> lock(m);
                        seen.insert({b, e});
                        ++calls;
                    });
                });
                EXPECT_EQ(seen, expected_blocks(n, block)) << "n " << n << " block " << block << " threads " << threads;
                EXPECT_EQ(calls, seen.size()) << "a block ran twice";
                EXPECT_EQ(atlas::block_count(n, block), seen.size());
            }
        }
    }
}

TEST(Parallel, ForEachVisitsEveryIndexOnce) {
    const size_t n = 10007;
    for (int threads : kThreadCounts) {
        std::vector<std::atomic<int>> hits(n);
        in_arena(threads, [&] { atlas::parallel_for_each(n, 100, [&](size_t i) { hits[i].fetch_add(1); }); });
        for (size_t i = 0; i < n; ++i) ASSERT_EQ(hits[i].load(), 1) << "index " << i << " threads " << threads;
    }
}

TEST(Parallel, ForIndexVisitsEveryIndexOnce) {
    for (int n : {-3, 0, 1, 17, 300}) {
        for (int threads : kThreadCounts) {
            std::vector<std::atomic<int>> hits(size_t(std::max(n, 0)));
            in_arena(threads, [&] { atlas::parallel_for_index(n, [&](int k) { hits[size_t(k)].fetch_add(1); }); });
            for (auto& h : hits) ASSERT_EQ(h.load(), 1) << "n " << n << " threads " << threads;
        }
    }
}

// A float sum is not associative, so only a fixed split and a fixed combining order
// give the same bits everywhere; the reference is a plain serial loop over the blocks.
TEST(Parallel, ReduceMatchesSerialBlockOrderOnAnyThreadCount) {
    const size_t n = 100003, block = 1000;
    std::vector<float> v(n);
    for (size_t i = 0; i < n; ++i) v[i] = float(std::sin(double(i) * 0.37) * std::pow(10.0, double(i % 9) - 4));
    float reference = 0.0f;
    for (size_t b = 0; b < n; b += block) {
        float part = 0.0f;
        for (size_t i = b; i < std::min(n, b + block); ++i) part += v[i];
        reference += part;
    }
    for (int threads : kThreadCounts) {
        const float got = in_arena(threads, [&] {
            return atlas::parallel_reduce_blocks(
                n, block, 0.0f,
                [&](size_t b, size_t e) {
                    float part = 0.0f;
                    for (size_t i = b; i < e; ++i) part += v[i];
                    return part;
                },
                [](float a, float b) { return a + b; });
        });
        uint32_t gb, rb;
        std::memcpy(&gb, &got, 4);
        std::memcpy(&rb, &reference, 4);
        EXPECT_EQ(gb, rb) << "threads " << threads << ": " << got << " vs " << reference;
    }
}

TEST(Parallel, ExceptionsPropagate) {
    EXPECT_THROW(atlas::parallel_for_each(10000, 10, [](size_t i) {
                     if (i == 5555) throw std::runtime_error("boom");
                 }),
                 std::runtime_error);
}

} // namespace

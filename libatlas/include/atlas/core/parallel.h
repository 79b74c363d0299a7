// atlas/core/parallel.h - deterministic parallel loops over fixed blocks (TBB underneath).
//
// The one parallel-for of the library: every module splits its work with these, so the
// rule "the split never depends on the thread count" lives in one place. Each loop cuts
// [0, n) into blocks of a fixed size chosen by the caller; which thread runs a block may
// vary, but the blocks themselves do not. Work that writes each element from exactly one
// block (element-wise maps, per-slice stencils) therefore gives the same bytes for any
// number of threads, and a reduction that stores one partial per block and combines the
// partials in block order (parallel_reduce_blocks) is deterministic too.
//
// Thread-safety: fn is called concurrently from several threads for different blocks;
// it must not write state shared between blocks. An exception thrown by fn propagates
// out of the loop (TBB cancels the remaining blocks).
//
// Header-only.
#pragma once

#include "atlas/core/progress.h"

#include <tbb/info.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cstddef>
#include <utility>
#include <vector>

namespace atlas {

// Number of blocks of `block` elements covering n elements (block >= 1).
constexpr size_t block_count(size_t n, size_t block) { return (n + block - 1) / block; }

// Calls fn(begin, end) for each fixed block [b * block, min(n, (b + 1) * block)) of
// [0, n), in parallel when there is more than one block (a single block runs on the
// calling thread). block >= 1.
// Between blocks the loop polls the cook's cancellation check (progress.h), so
// every long loop stops on Ctrl-C; blocks never split differently for it.
template <typename Fn>
void parallel_blocks(size_t n, size_t block, Fn&& fn) {
    const size_t blocks = block_count(n, block);
    const auto* cancel = detail::current_cancel();
    if (blocks <= 1) {
        detail::poll_cancel(cancel);
        if (n > 0) fn(size_t(0), n);
        return;
    }
    tbb::parallel_for(size_t(0), blocks, [&](size_t b) {
        const detail::CancelScope scope(cancel); // nested loops on this thread see it too
        detail::poll_cancel(cancel);
        fn(b * block, std::min(n, (b + 1) * block));
    });
}

// Calls fn(i) for every i in [0, n), in fixed blocks of `block` indices.
template <typename Fn>
void parallel_for_each(size_t n, size_t block, Fn&& fn) {
    parallel_blocks(n, block, [&](size_t i0, size_t i1) {
        for (size_t i = i0; i != i1; ++i) fn(i);
    });
}

// Calls fn(k) for every k in [0, n), one task per index: for loops whose index is a
// slice or a row (each call does a lot of work). n <= 0 does nothing.
template <typename Fn>
void parallel_for_index(int n, Fn&& fn) {
    if (n <= 0) return;
    const auto* cancel = detail::current_cancel();
    tbb::parallel_for(0, n, [&](int k) {
        const detail::CancelScope scope(cancel);
        detail::poll_cancel(cancel);
        fn(k);
    });
}

// Deterministic reduction: partial = fn(begin, end) per fixed block, combined as
// combine(...combine(combine(init, p0), p1)..., p_last) in block order on the calling
// thread. Same value for any thread count.
template <typename T, typename Fn, typename Combine>
T parallel_reduce_blocks(size_t n, size_t block, T init, Fn&& fn, Combine&& combine) {
    std::vector<T> partial(block_count(n, block), init);
    parallel_blocks(n, block, [&](size_t i0, size_t i1) { partial[i0 / block] = fn(i0, i1); });
    T acc = init;
    for (const T& p : partial) acc = combine(acc, p);
    return acc;
}

// Runs a and b, possibly at the same time on two threads; returns when both are done.
// Two independent computations (each writing only its own result) stay deterministic.
template <typename A, typename B>
void parallel_invoke(A&& a, B&& b) {
    tbb::parallel_invoke(std::forward<A>(a), std::forward<B>(b));
}

// Threads a loop may use when nothing limits it (the machine's hardware concurrency).
inline int hardware_threads() { return int(tbb::info::default_concurrency()); }

// A limit on the worker threads of the loops run through it (<= 0: no limit), kept
// for several runs (a cook's levels or tiles). The limit changes which thread runs a
// block, never the blocks themselves.
class ThreadLimit {
public:
    explicit ThreadLimit(int threads) : threads_(threads > 0 ? threads : hardware_threads()), arena_(threads_) {}
    int threads() const { return threads_; }
    template <typename Fn>
    void run(Fn&& fn) {
        arena_.execute(fn);
    }

private:
    int threads_;
    tbb::task_arena arena_;
};

// Runs fn() with the loops inside it limited to `threads` worker threads (<= 0: no limit).
template <typename Fn>
void with_thread_limit(int threads, Fn&& fn) {
    if (threads <= 0) {
        fn();
        return;
    }
    ThreadLimit(threads).run(fn);
}

} // namespace atlas

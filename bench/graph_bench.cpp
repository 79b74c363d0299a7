// Evaluator overhead and the quickstart cook: how long hashing, cache lookups
// and scheduling take compared with the work itself.
#include "atlas/graph/evaluator.h"

#include <benchmark/benchmark.h>

#include <string>

namespace {

// A chain of `n` cheap math nodes over a small field: measures per-node overhead.
std::string chain_graph(int n, int res) {
    std::string g = "atlas: 1\nnodes:\n  n0:\n    type: field/constant\n    params: {resolution: [" + std::to_string(res) + ", " +
                    std::to_string(res) + ", 4], value: 1}\n";
    for (int i = 1; i <= n; ++i)
        g += "  n" + std::to_string(i) + ":\n    type: math/binary\n    inputs: {a: n" + std::to_string(i - 1) +
             "}\n    params: {op: add, b: 1}\n";
    g += "outputs:\n  - {node: n" + std::to_string(n) + ", file: x.exr}\n";
    return g;
}

void ChainCold(benchmark::State& state) {
    const std::string g = chain_graph(int(state.range(0)), 16);
    for (auto _ : state) {
        atlas::Session s(atlas::builtin_nodes());
        s.load_text(g, "chain.yaml", ".");
        atlas::CookOptions o;
        o.write_outputs = false;
        benchmark::DoNotOptimize(s.cook(o));
    }
    state.counters["nodes/s"] = benchmark::Counter(double(state.iterations() * (state.range(0) + 1)), benchmark::Counter::kIsRate);
}

void ChainCached(benchmark::State& state) {
    const std::string g = chain_graph(int(state.range(0)), 16);
    atlas::Session s(atlas::builtin_nodes());
    s.load_text(g, "chain.yaml", ".");
    atlas::CookOptions o;
    o.write_outputs = false;
    s.cook(o);
    for (auto _ : state) benchmark::DoNotOptimize(s.cook(o)); // everything from cache
}

void Quickstart(benchmark::State& state) {
    for (auto _ : state) {
        atlas::Session s(atlas::builtin_nodes());
        s.load(std::string(ATLAS_SOURCE_DIR) + "/examples/quickstart.yaml");
        atlas::CookOptions o;
        o.write_outputs = false;
        o.jobs = int(state.range(0));
        benchmark::DoNotOptimize(s.cook(o));
    }
}

void SmokeChain(benchmark::State& state) { ChainCold(state); }

} // namespace

BENCHMARK(ChainCold)->Arg(10)->Arg(100)->Unit(benchmark::kMillisecond);
BENCHMARK(ChainCached)->Arg(100)->Unit(benchmark::kMicrosecond);
BENCHMARK(Quickstart)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond);
BENCHMARK(SmokeChain)->Arg(3)->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();

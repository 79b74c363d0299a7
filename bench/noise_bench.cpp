// Noise kernels (samples/s, one octave, 1 thread and all threads) and the
// production recipes (Nubis 128^3 x 4, HZD set). "Smoke" variants are tiny
// for ctest (--benchmark_filter=Smoke).
#include "atlas/noise/fill.h"
#include "atlas/noise/recipes.h"

#include <benchmark/benchmark.h>
#include <tbb/info.h>
#include <tbb/task_arena.h>

namespace {
using namespace atlas;
using namespace atlas::noise;

NoiseSpec kernel_spec(Kernel k) {
    NoiseSpec s;
    s.kernel = k;
    s.period = {{8, 8, 8}};
    s.seed = 1;
    s.worley.feature = WorleyFeature::F1;
    return s;
}

// state.range(0): kernel, range(1): threads (0 = all), range(2): edge.
void BM_Kernel3D(benchmark::State& state) {
    const Kernel k = Kernel(state.range(0));
    const int threads = state.range(1) == 0 ? tbb::info::default_concurrency() : int(state.range(1));
    const int n = int(state.range(2));
    Field3D f({{n, n, n}}, noise_components(k, 3), Box3d{{{0, 0, 0}}, {{1, 1, 1}}});
    const NoiseSpec s = kernel_spec(k);
    tbb::task_arena arena(threads);
    for (auto _ : state) {
        arena.execute([&] { fill_noise(f, 0, s); });
        benchmark::DoNotOptimize(f.channel(0).data());
    }
    state.SetItemsProcessed(state.iterations() * int64_t(n) * n * n);
    state.SetLabel(std::string(kernel_name(k)) + ", " + std::to_string(threads) + " thread(s)");
}

void kernel_args(benchmark::internal::Benchmark* b, int edge) {
    for (Kernel k : {Kernel::Gradient, Kernel::Worley, Kernel::Alligator, Kernel::Curl})
        for (int t : {1, 0}) b->Args({int64_t(k), t, edge});
}

BENCHMARK(BM_Kernel3D)->Apply([](auto* b) { kernel_args(b, 64); })->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Kernel3D)->Name("BM_Kernel3D_Smoke")->Apply([](auto* b) { kernel_args(b, 8); })->UseRealTime();

void BM_NubisNoise(benchmark::State& state) {
    const int n = int(state.range(0));
    for (auto _ : state) benchmark::DoNotOptimize(make_nubis_noise(n, 0));
    state.SetItemsProcessed(state.iterations() * int64_t(n) * n * n * 4);
}
BENCHMARK(BM_NubisNoise)->Arg(128)->Unit(benchmark::kSecond)->UseRealTime()->Iterations(1);
BENCHMARK(BM_NubisNoise)->Name("BM_NubisNoise_Smoke")->Arg(8)->UseRealTime();

void BM_HzdNoise(benchmark::State& state) {
    const int n = int(state.range(0)), hi = int(state.range(1)), curl = int(state.range(2));
    for (auto _ : state) benchmark::DoNotOptimize(make_hzd_noise(n, hi, curl, 0));
}
BENCHMARK(BM_HzdNoise)->Args({128, 32, 128})->Unit(benchmark::kSecond)->UseRealTime()->Iterations(1);
BENCHMARK(BM_HzdNoise)->Name("BM_HzdNoise_Smoke")->Args({8, 4, 8})->UseRealTime();

} // namespace

BENCHMARK_MAIN();

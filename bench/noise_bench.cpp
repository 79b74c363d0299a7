// Noise kernels (samples/s, one octave, 1 thread and all threads) and the
// production recipes (Nubis 128^3 x 4, HZD set). "Smoke" variants are tiny
// for ctest (--benchmark_filter=Smoke).
#include "atlas/noise/fill.h"
#include "atlas/noise/recipes.h"
#include "atlas/noise/simd.h"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <string>
#include <vector>
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

// Selects the SIMD path a benchmark asks for (0 = auto); false (and the
// benchmark skipped) when this machine lacks it.
bool use_path(benchmark::State& state, int64_t path) {
    const SimdPath p = path > 0 ? SimdPath(path) : SimdPath::Auto;
    const auto paths = supported_simd_paths();
    if (p != SimdPath::Auto && std::find(paths.begin(), paths.end(), p) == paths.end()) {
        state.SkipWithError("SIMD path not supported here");
        return false;
    }
    set_simd_path(p);
    return true;
}

// state.range(0): kernel, range(1): threads (0 = all), range(2): edge,
// range(3): SimdPath (0 = auto; ATLAS_SIMD also selects it); always given, since
// reading an argument past the registered ones reads past Benchmark's vector.
void BM_Kernel3D(benchmark::State& state) {
    const Kernel k = Kernel(state.range(0));
    const int threads = state.range(1) == 0 ? tbb::info::default_concurrency() : int(state.range(1));
    const int n = int(state.range(2));
    if (!use_path(state, state.range(3))) return;
    Field3D f({{n, n, n}}, noise_components(k, 3), Box3d{{{0, 0, 0}}, {{1, 1, 1}}});
    const NoiseSpec s = kernel_spec(k);
    tbb::task_arena arena(threads);
    for (auto _ : state) {
        arena.execute([&] { fill_noise(f, 0, s); });
        benchmark::DoNotOptimize(f.channel(0).data());
    }
    state.SetItemsProcessed(state.iterations() * int64_t(n) * n * n);
    state.SetLabel(std::string(kernel_name(k)) + ", " + std::to_string(threads) + " thread(s), " + simd_path_name(simd_path()));
    set_simd_path(SimdPath::Auto);
}

void kernel_args(benchmark::internal::Benchmark* b, int edge) {
    for (Kernel k : {Kernel::Gradient, Kernel::Worley, Kernel::Alligator, Kernel::Curl})
        for (int t : {1, 0}) b->Args({int64_t(k), t, edge, 0}); // range(3) 0: the auto path
}

BENCHMARK(BM_Kernel3D)->Apply([](auto* b) { kernel_args(b, 64); })->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Kernel3D)->Name("BM_Kernel3D_Smoke")->Apply([](auto* b) { kernel_args(b, 8); })->UseRealTime();

// Side by side with FastNoiseLite (-O3 -march=native, noise_peer_fnl.cpp), one
// thread, period 8 (8 lattice cells per edge, as kernel_spec), edges 32, 64, 128
// (cost growth), each SIMD path: BM_Peer3D/<kernel>/<edge>/<path>, path 0 = auto.
// Kernels: 0 Perlin, 2 Worley F1 Euclidean (Kernel enum values).
void BM_Peer3D_Atlas(benchmark::State& state) {
    const int64_t k = state.range(0), n = state.range(1), path = state.range(2);
    if (!use_path(state, path)) return;
    Field3D f({{int(n), int(n), int(n)}}, 1, Box3d{{{0, 0, 0}}, {{1, 1, 1}}});
    const NoiseSpec s = kernel_spec(Kernel(k));
    tbb::task_arena arena(1);
    for (auto _ : state) {
        arena.execute([&] { fill_noise(f, 0, s); });
        benchmark::DoNotOptimize(f.channel(0).data());
    }
    state.SetItemsProcessed(state.iterations() * n * n * n);
    state.SetLabel(std::string("atlas ") + std::string(kernel_name(Kernel(k))) + ", " + simd_path_name(simd_path()));
    set_simd_path(SimdPath::Auto);
}
BENCHMARK(BM_Peer3D_Atlas)->ArgsProduct({{int64_t(Kernel::Gradient), int64_t(Kernel::Worley)}, {32, 64, 128}, {1, 2, 3, 4}})->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Peer3D_Atlas)->Name("BM_Peer3D_Atlas_Smoke")->Args({0, 8, 0})->Args({2, 8, 0});

// Perlin on lattices too large to tabulate (issue 49: period > 128 per axis, or an
// FBM's high octaves): BM_GradientLattice/<period>/<octaves>/<path>, 128^3, one
// thread; period 128 is tabulated, 256 hashed; period 8 with 8 octaves reaches
// 1024 cells per edge at the last octave.
void BM_GradientLattice(benchmark::State& state) {
    const int period = int(state.range(0)), octaves = int(state.range(1));
    if (!use_path(state, state.range(2))) return;
    const int n = 128;
    Field3D f({{n, n, n}}, 1, Box3d{{{0, 0, 0}}, {{1, 1, 1}}});
    NoiseSpec s = kernel_spec(Kernel::Gradient);
    s.period = {{period, period, period}};
    s.fractal.octaves = octaves;
    tbb::task_arena arena(1);
    for (auto _ : state) {
        arena.execute([&] { fill_noise(f, 0, s); });
        benchmark::DoNotOptimize(f.channel(0).data());
    }
    state.SetItemsProcessed(state.iterations() * int64_t(n) * n * n);
    state.SetLabel("period " + std::to_string(period) + ", " + std::to_string(octaves) + " octave(s), " + simd_path_name(simd_path()));
    set_simd_path(SimdPath::Auto);
}
BENCHMARK(BM_GradientLattice)->ArgsProduct({{128, 256}, {1}, {1, 2, 3, 4}})->Args({8, 8, 1})->Args({8, 8, 2})->Args({8, 8, 3})->Args({8, 8, 4})->Unit(benchmark::kMillisecond);

#if defined(ATLAS_BENCH_FNL)
} // namespace
namespace atlas_peer {
void fnl_fill(int kind, int n, int cells, int seed, float* out);
}
namespace {
void BM_Peer3D_FastNoiseLite(benchmark::State& state) {
    const int64_t k = state.range(0), n = state.range(1);
    std::vector<float> out(size_t(n * n * n));
    for (auto _ : state) {
        atlas_peer::fnl_fill(k == int64_t(Kernel::Gradient) ? 0 : 1, int(n), 8, 1, out.data());
        benchmark::DoNotOptimize(out.data());
    }
    state.SetItemsProcessed(state.iterations() * n * n * n);
    state.SetLabel(k == int64_t(Kernel::Gradient) ? "FastNoiseLite Perlin" : "FastNoiseLite cellular F1 Euclidean");
}
BENCHMARK(BM_Peer3D_FastNoiseLite)->ArgsProduct({{int64_t(Kernel::Gradient), int64_t(Kernel::Worley)}, {32, 64, 128}})->Unit(benchmark::kMillisecond);
#endif

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

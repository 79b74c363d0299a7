// Volume benchmarks: whole-grid SDF (exact EDT vs OpenVDB fast sweeping) and
// mesh to SDF. Error columns: the fast-sweeping result against the EDT (exact
// with respect to the crossing points), in voxels.
#include "atlas/volume/sdf.h"

#include <benchmark/benchmark.h>

#include <cmath>
#include <random>

namespace {
using namespace atlas;
using namespace atlas::volume;

// Cumulus-like density: overlapping spheres with a linear ramp at the edge.
Field3D cloud_density(Vec3i res, double h, unsigned seed) {
    Field3D f(res, 1, {{{0, 0, 0}}, {{res[0] * h, res[1] * h, res[2] * h}}});
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0, 1);
    const int n = std::max(4, res[0] * res[1] / 2048);
    for (int b = 0; b < n; ++b) {
        const double r = (3 + 10 * u(rng)) * h * res[2] / 64.0;
        const Vec3d c{{u(rng) * res[0] * h, u(rng) * res[1] * h, (0.3 + 0.3 * u(rng)) * res[2] * h}};
        const int x0 = std::max(0, int((c[0] - r) / h) - 2), x1 = std::min(res[0] - 1, int((c[0] + r) / h) + 2);
        const int y0 = std::max(0, int((c[1] - r) / h) - 2), y1 = std::min(res[1] - 1, int((c[1] + r) / h) + 2);
        const int z0 = std::max(0, int((c[2] - r) / h) - 2), z1 = std::min(res[2] - 1, int((c[2] + r) / h) + 2);
        for (int z = z0; z <= z1; ++z)
            for (int y = y0; y <= y1; ++y)
                for (int x = x0; x <= x1; ++x) {
                    const double d = (length(f.voxel_center(x, y, z) - c) - r) / h;
                    float& v = f.at(0, x, y, z);
                    v = std::max(v, float(std::clamp(0.5 - d / 2, 0.0, 1.0)));
                }
    }
    return f;
}

void run_sdf(benchmark::State& state, Vec3i res, bool sweeping) {
    const Field3D d = cloud_density(res, 8.0, 5);
    SdfOptions o;
    SdfStats st;
    Field3D out = sweeping ? sdf_from_density_fast_sweeping(d, o, 1, nullptr, &st) : sdf_from_density_edt(d, o, nullptr, &st);
    for (auto _ : state) {
        out = sweeping ? sdf_from_density_fast_sweeping(d, o, 1, nullptr, &st) : sdf_from_density_edt(d, o, nullptr, &st);
        benchmark::DoNotOptimize(out.channel(0).data());
    }
    if (sweeping) {
        // fogToSdf sees beyond the grid as empty: compare with the EDT doing the same.
        o.border_is_outside = true;
        const SdfError e = compare_sdf(out, sdf_from_density_edt(d, o));
        state.counters["max_err_vox"] = e.max_abs_voxels;
        state.counters["rms_err_vox"] = e.rms_voxels;
        state.counters["sign_err"] = double(e.sign_mismatches);
    }
    state.counters["crossings"] = double(st.crossings);
    state.counters["Mvox/s"] = benchmark::Counter(double(d.voxel_count()) * double(state.iterations()) / 1e6, benchmark::Counter::kIsRate);
}

void BM_SdfEdt_512x512x64(benchmark::State& s) { run_sdf(s, {{512, 512, 64}}, false); }
void BM_SdfFastSweeping_512x512x64(benchmark::State& s) { run_sdf(s, {{512, 512, 64}}, true); }
void BM_SdfEdt_Smoke(benchmark::State& s) { run_sdf(s, {{32, 32, 8}}, false); }
void BM_SdfFastSweeping_Smoke(benchmark::State& s) { run_sdf(s, {{32, 32, 8}}, true); }

} // namespace

BENCHMARK(BM_SdfEdt_512x512x64)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_SdfFastSweeping_512x512x64)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_SdfEdt_Smoke)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_SdfFastSweeping_Smoke)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_MAIN();

// Volume benchmarks: whole-grid SDF (exact EDT vs OpenVDB fast sweeping) and
// mesh to SDF. Error columns: the fast-sweeping result against the EDT (exact
// with respect to the crossing points), in voxels.
#include "atlas/volume/mesh_io.h"
#include "atlas/volume/mesh_primitives.h"
#include "atlas/volume/mesh_voxelize.h"
#include "atlas/volume/sdf.h"

#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
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

// A bumpy sphere (cauliflower-like cloud shape) of about `triangles` triangles.
Mesh bumpy_sphere(int triangles) {
    const int slices = int(std::sqrt(triangles)), stacks = std::max(2, slices / 2);
    Mesh m = make_sphere_mesh({{128, 128, 128}}, 90, stacks, slices);
    for (auto& v : m.vertices) {
        const double x = v[0] - 128, y = v[1] - 128, z = v[2] - 128;
        const double r = std::sqrt(x * x + y * y + z * z);
        const double k = 1 + 0.12 * std::sin(x * 0.09) * std::sin(y * 0.08) * std::sin(z * 0.07 + 1);
        v = {{float(128 + x * k), float(128 + y * k), float(128 + z * k)}};
        (void)r;
    }
    return m;
}

void run_mesh_sdf(benchmark::State& state, int triangles, int res, bool openvdb) {
    const Mesh m = bumpy_sphere(triangles);
    if (const char* dir = std::getenv("ATLAS_BENCH_MESH_DIR"))
        write_mesh(std::filesystem::path(dir) / ("bench_mesh_" + std::to_string(m.triangles.size()) + ".obj"), m);
    const Box3d box{{{0, 0, 0}}, {{256, 256, 256}}};
    const Vec3i r{{res, res, res}};
    MeshSdfStats st;
    Field3D out = openvdb ? mesh_to_sdf_openvdb(m, r, box, nullptr, &st) : mesh_to_sdf(m, r, box, {}, nullptr, &st);
    for (auto _ : state) {
        out = openvdb ? mesh_to_sdf_openvdb(m, r, box, nullptr, &st) : mesh_to_sdf(m, r, box, {}, nullptr, &st);
        benchmark::DoNotOptimize(out.channel(0).data());
    }
    if (openvdb) {
        const SdfError e = compare_sdf(out, mesh_to_sdf(m, r, box));
        state.counters["max_diff_vs_edt_vox"] = e.max_abs_voxels;
        state.counters["rms_diff_vs_edt_vox"] = e.rms_voxels;
        state.counters["sign_diff"] = double(e.sign_mismatches);
    }
    state.counters["triangles"] = double(m.triangles.size());
    state.counters["line_hits"] = double(st.line_hits);
}

void BM_MeshSdfEdt_100k_256(benchmark::State& s) { run_mesh_sdf(s, 100000, 256, false); }
void BM_MeshSdfOpenVdb_100k_256(benchmark::State& s) { run_mesh_sdf(s, 100000, 256, true); }
void BM_MeshSdfEdt_Smoke(benchmark::State& s) { run_mesh_sdf(s, 2000, 32, false); }
void BM_MeshSdfOpenVdb_Smoke(benchmark::State& s) { run_mesh_sdf(s, 2000, 32, true); }

} // namespace

BENCHMARK(BM_MeshSdfEdt_100k_256)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_MeshSdfOpenVdb_100k_256)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_MeshSdfEdt_Smoke)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_MeshSdfOpenVdb_Smoke)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_SdfEdt_512x512x64)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_SdfFastSweeping_512x512x64)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_SdfEdt_Smoke)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_SdfFastSweeping_Smoke)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_MAIN();

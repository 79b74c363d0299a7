// Volume benchmarks: whole-grid SDF (exact EDT vs OpenVDB fast sweeping) and
// mesh to SDF. Error columns: the fast-sweeping result against the EDT (exact
// with respect to the crossing points), in voxels.
#include "atlas/io/geometry_files.h"
#include "atlas/volume/mesh_repair.h"
#include "atlas/volume/mesh_primitives.h"
#include "atlas/volume/mesh_voxelize.h"
#include "atlas/volume/sdf.h"

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <benchmark/benchmark.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/MeshToVolume.h>
#include <unistd.h>

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
        io::write_mesh(std::filesystem::path(dir) / ("bench_mesh_" + std::to_string(m.triangles.size()) + ".obj"), m);
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

// The CGAL demo data's armadillo (52k triangles; libcgal-demo, scripts/setup.sh), or
// $ATLAS_BENCH_ARMADILLO. Grid: a 160-unit cube about the mesh's box centre (the mesh
// spans 127 x 151 x 115), so N^3 voxels of 160 / N.
const Mesh& armadillo() {
    static const Mesh m = [] {
        std::filesystem::path file;
        if (const char* f = std::getenv("ATLAS_BENCH_ARMADILLO")) file = f;
        else {
            const auto dir = std::filesystem::temp_directory_path() / ("atlas_armadillo_" + std::to_string(::getpid()));
            std::filesystem::create_directories(dir);
            const std::string cmd = "tar -xzf /usr/share/doc/libcgal-demo/data.tar.gz -C " + dir.string() + " data/meshes/armadillo.off";
            if (std::system(cmd.c_str()) != 0) return Mesh{};
            file = dir / "data/meshes/armadillo.off";
        }
        return repair_polygon_soup(io::read_polygon_soup(file));
    }();
    return m;
}

Box3d armadillo_box() {
    const Mesh& m = armadillo();
    Vec3d lo{{1e30, 1e30, 1e30}}, hi{{-1e30, -1e30, -1e30}};
    for (const Vec3f& v : m.vertices)
        for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], double(v[k])), hi[k] = std::max(hi[k], double(v[k]));
    const Vec3d c = (lo + hi) * 0.5;
    return {c - Vec3d{{80, 80, 80}}, c + Vec3d{{80, 80, 80}}};
}

// Atlas: the whole N^3 grid (method edt or openvdb), from the mesh in memory.
void run_armadillo(benchmark::State& state, bool openvdb) {
    const Mesh& m = armadillo();
    if (m.triangles.empty()) return state.SkipWithError("no armadillo (libcgal-demo)");
    const int n = int(state.range(0));
    const Vec3i r{{n, n, n}};
    const Box3d box = armadillo_box();
    MeshSdfStats st;
    for (auto _ : state) {
        Field3D out = openvdb ? mesh_to_sdf_openvdb(m, r, box, nullptr, &st) : mesh_to_sdf(m, r, box, {}, nullptr, &st);
        benchmark::DoNotOptimize(out.channel(0).data());
    }
    state.counters["triangles"] = double(m.triangles.size());
    state.counters["Mvox"] = double(n) * n * n / 1e6;
}
void BM_ArmadilloAtlasEdt(benchmark::State& s) { run_armadillo(s, false); }
void BM_ArmadilloAtlasOpenVdb(benchmark::State& s) { run_armadillo(s, true); }

// The peer: what `vdb_tool -read armadillo.obj -mesh2ls voxel=160/N width=3` runs
// (openvdb::tools::meshToLevelSet, a +-3-voxel narrow band), from the same mesh in memory.
void BM_ArmadilloVdbMeshToLevelSet(benchmark::State& state) {
    const Mesh& m = armadillo();
    if (m.triangles.empty()) return state.SkipWithError("no armadillo (libcgal-demo)");
    openvdb::initialize();
    const int n = int(state.range(0));
    auto xf = openvdb::math::Transform::createLinearTransform(160.0 / n);
    std::vector<openvdb::Vec3s> pts;
    std::vector<openvdb::Vec3I> tris;
    for (const Vec3f& v : m.vertices) pts.emplace_back(v[0], v[1], v[2]);
    for (const auto& t : m.triangles) tris.emplace_back(t[0], t[1], t[2]);
    uint64_t active = 0;
    for (auto _ : state) {
        auto grid = openvdb::tools::meshToLevelSet<openvdb::FloatGrid>(*xf, pts, tris, 3.0f);
        active = grid->activeVoxelCount();
        benchmark::DoNotOptimize(grid.get());
    }
    state.counters["active_Mvox"] = double(active) / 1e6;
    state.counters["Mvox"] = double(n) * n * n / 1e6;
}

// Accuracy of the whole 256^3 armadillo grid against an independent reference: CGAL's
// AABB tree (exact point-triangle distance to all 52k triangles) and the parity of a
// CGAL ray cast for the sign (the armadillo is closed), on every 61st voxel (275k).
// Band: |d| <= 1.5 voxels (the exact band of `edt`, as in the MeshSdf tests); near: 1.5 to
// 3 voxels (the rest of vdb_tool's band); far: beyond.
void run_armadillo_accuracy(benchmark::State& state, bool openvdb) {
    using K = CGAL::Exact_predicates_inexact_constructions_kernel;
    using Tri = K::Triangle_3;
    using Tree = CGAL::AABB_tree<CGAL::AABB_traits<K, CGAL::AABB_triangle_primitive<K, std::vector<Tri>::const_iterator>>>;
    const Mesh& m = armadillo();
    if (m.triangles.empty()) return state.SkipWithError("no armadillo (libcgal-demo)");
    const int n = int(state.range(0));
    const Box3d box = armadillo_box();
    Field3D out = openvdb ? mesh_to_sdf_openvdb(m, {{n, n, n}}, box) : mesh_to_sdf(m, {{n, n, n}}, box);
    for (auto _ : state) benchmark::DoNotOptimize(out.channel(0).data());
    std::vector<Tri> tris;
    auto P = [&](uint32_t i) { return K::Point_3(m.vertices[i][0], m.vertices[i][1], m.vertices[i][2]); };
    for (const auto& t : m.triangles) tris.emplace_back(P(t[0]), P(t[1]), P(t[2]));
    Tree tree(tris.begin(), tris.end());
    tree.accelerate_distance_queries();
    const double h = 160.0 / n;
    double band = 0, near = 0, far = 0;
    uint64_t sign = 0, samples = 0;
    for (size_t i = 0; i < out.voxel_count(); i += 61) {
        const int x = int(i % size_t(n)), y = int(i / size_t(n) % size_t(n)), z = int(i / (size_t(n) * n));
        const Vec3d p = out.voxel_center(x, y, z);
        const K::Point_3 q(p[0], p[1], p[2]);
        const double d = std::sqrt(tree.squared_distance(q));
        // An irrational-ish direction: no ray through an edge or vertex in practice.
        const K::Ray_3 ray(q, K::Vector_3(0.5773, 0.6123, 0.5401));
        const bool inside = tree.number_of_intersected_primitives(ray) % 2 == 1;
        const double got = out.channel(0)[i];
        sign += (got < 0) != inside;
        const double e = std::abs(std::abs(got) - d) / h;
        double& worst = d <= 1.5 * h ? band : d <= 3 * h ? near : far;
        worst = std::max(worst, e);
        ++samples;
    }
    state.counters["band_err_vox"] = band;
    state.counters["near_err_vox"] = near;
    state.counters["far_err_vox"] = far;
    state.counters["sign_err"] = double(sign);
    state.counters["samples"] = double(samples);
}
void BM_ArmadilloAccuracyEdt(benchmark::State& s) { run_armadillo_accuracy(s, false); }
void BM_ArmadilloAccuracyOpenVdb(benchmark::State& s) { run_armadillo_accuracy(s, true); }

} // namespace

// Atlas against vdb_tool's call at three sizes (docs/PERFORMANCE.md: wall and process CPU,
// run with --benchmark_enable_random_interleaving=true --benchmark_repetitions=N).
BENCHMARK(BM_ArmadilloAtlasEdt)->Arg(128)->Arg(256)->Arg(384)->Unit(benchmark::kMillisecond)->UseRealTime()->MeasureProcessCPUTime();
BENCHMARK(BM_ArmadilloAtlasOpenVdb)->Arg(128)->Arg(256)->Arg(384)->Unit(benchmark::kMillisecond)->UseRealTime()->MeasureProcessCPUTime();
BENCHMARK(BM_ArmadilloVdbMeshToLevelSet)->Arg(128)->Arg(256)->Arg(384)->Unit(benchmark::kMillisecond)->UseRealTime()->MeasureProcessCPUTime();
BENCHMARK(BM_ArmadilloAccuracyEdt)->Arg(256)->Iterations(1)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_ArmadilloAccuracyOpenVdb)->Arg(256)->Iterations(1)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_MeshSdfEdt_100k_256)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_MeshSdfOpenVdb_100k_256)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_MeshSdfEdt_Smoke)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_MeshSdfOpenVdb_Smoke)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_SdfEdt_512x512x64)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_SdfFastSweeping_512x512x64)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_SdfEdt_Smoke)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_SdfFastSweeping_Smoke)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_MAIN();

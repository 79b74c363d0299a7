// Preview renderer benchmarks: 960x540 fast mode from a ground camera and
// from inside a cloud, and the RMSE of the fast mode against the reference
// (at 240x135: the reference marches every light ray and is slow).
// Scene: the NVDF set in $ATLAS_RENDER_BENCH_SCENE (e.g. graphs/cloudscape.yaml's
// nvdf/cloudscape.vdb, cooked with `atlas cook`), else a synthetic cloudscape
// of metaball-like spheres over the same 4096 x 4096 x 512 m domain.
// Smoke variants are tiny and only prove the code runs.
#include "atlas/io/readers.h"
#include "atlas/noise/value_noise.h"
#include "atlas/render/renderer.h"
#include "atlas/render/sweep.h"

#include <benchmark/benchmark.h>

#include <sys/resource.h>

#include <chrono>
#include <cstdlib>
#include <memory>

namespace {
using namespace atlas;
using namespace atlas::render;

Field3DPtr bench_noise(int res) {
    auto n = std::make_shared<Field3D>(Vec3i{{res, res, res}}, 4, Box3d{{{0, 0, 0}}, {{1, 1, 1}}});
    const int periods[4] = {4, 8, 6, 12};
    for (int c = 0; c < 4; ++c)
        for (int z = 0; z < res; ++z)
            for (int y = 0; y < res; ++y) {
                const double f = double(periods[c]) / res;
                auto row = n->channel(c).subspan(n->index(0, y, z), size_t(res));
                noise::value_noise_row(row, 0.5 * f, f, (y + 0.5) * f, (z + 0.5) * f, Vec3i{{periods[c], periods[c], periods[c]}},
                                       uint32_t(3 + c));
            }
    return n;
}

CloudScene synthetic_cloudscape(Vec3i res) {
    const Box3d b{{{0, 0, 0}}, {{4096, 4096, 512}}};
    auto m = std::make_shared<Field3D>(res, 3, b, std::vector<std::string>{"dimensional_profile", "detail_type", "density_scale"});
    auto s = std::make_shared<Field3D>(res, 1, b, std::vector<std::string>{"sdf"});
    struct Ball { double x, y, z, r; };
    const Ball balls[] = {{900, 1400, 170, 190}, {1080, 1450, 200, 170}, {1000, 1250, 240, 150}, {1120, 1300, 300, 120},
                          {2700, 900, 190, 160}, {2900, 950, 200, 170}, {3100, 900, 190, 150}, {1500, 3200, 200, 130},
                          {2800, 2800, 240, 200}, {3000, 2600, 220, 160}, {2500, 2950, 230, 150}};
    for (int z = 0; z < res[2]; ++z)
        for (int y = 0; y < res[1]; ++y)
            for (int x = 0; x < res[0]; ++x) {
                const Vec3d p = m->voxel_center(x, y, z);
                double d = 1e9;
                for (const auto& bl : balls) d = std::min(d, length(p - Vec3d{{bl.x, bl.y, bl.z}}) - bl.r);
                s->at(0, x, y, z) = float(d);
                m->at(0, x, y, z) = float(std::clamp(-d / 64, 0.0, 1.0));
                m->at(1, x, y, z) = float(std::clamp((p[2] - 100) / 350, 0.0, 1.0) * 0.7 + 0.2);
                m->at(2, x, y, z) = 1.0f;
            }
    return {m, s, nullptr, 256};
}

const CloudScene& scene() {
    static const CloudScene s = [] {
        CloudScene c;
        if (const char* f = std::getenv("ATLAS_RENDER_BENCH_SCENE"); f && *f) c = scene_from_fields({{io::as_field3d(io::read_field_file(f)), f}});
        else c = synthetic_cloudscape({{512, 512, 64}});
        c.noise = bench_noise(64);
        c.noise_tile = 256;
        return c;
    }();
    return s;
}

const CloudScene& smoke_scene() {
    static const CloudScene s = [] {
        CloudScene c = synthetic_cloudscape({{32, 32, 8}});
        c.noise = bench_noise(8);
        return c;
    }();
    return s;
}

RenderSettings view(int which, int w, int h) {
    RenderSettings s;
    s.width = w;
    s.height = h;
    s.sun_direction = sun_direction(60, 35);
    if (which == 0) { // ground camera looking up at the clouds
        s.camera.position = {{2000, -300, 2}};
        s.camera.look_at = {{2000, 2000, 300}};
        s.camera.fov_deg = 60;
    } else { // inside cumulus A, looking across the cloudscape
        s.camera.position = {{1000, 1280, 240}};
        s.camera.look_at = {{3000, 2000, 240}};
        s.camera.fov_deg = 60;
    }
    return s;
}

// User + system CPU seconds of the whole process (all worker threads): on
// this shared 2-core VM the wall time depends on the other jobs running.
double process_cpu_seconds() {
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    return double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) + 1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

void fast(benchmark::State& st, const CloudScene& sc, int which, int w, int h, bool glow = false) {
    RenderSettings s = view(which, w, h);
    if (glow) {
        // Internal glow in cumulus A, B and the ring: three point lights, 4
        // density samples toward each per cloud sample.
        s.lights = {{{{1050, 1350, 220}}, {{1.0f, 0.25f, 0.1f}}, 4e4, 400},
                    {{{2900, 930, 190}}, {{1.0f, 0.25f, 0.1f}}, 4e4, 400},
                    {{{2800, 2800, 240}}, {{0.6f, 0.7f, 1.0f}}, 4e4, 400}};
    }
    uint64_t samples = 0;
    const double cpu0 = process_cpu_seconds();
    for (auto _ : st) {
        auto r = render_clouds(sc, s);
        samples = r.report.density_samples;
        benchmark::DoNotOptimize(r.image.channel(0).data());
    }
    st.counters["density_samples"] = double(samples);
    st.counters["process_cpu_s"] = (process_cpu_seconds() - cpu0) / double(st.iterations());
}

void error_vs_reference(benchmark::State& st, const CloudScene& sc, int which, int w, int h) {
    RenderSettings s = view(which, w, h);
    s.reference_step = 0.5 * std::min({sc.modeling->voxel_size()[0], sc.modeling->voxel_size()[1], sc.modeling->voxel_size()[2]});
    SweepResult r;
    for (auto _ : st) r = quality_sweep(sc, s, {1.0});
    st.counters["rmse"] = r.rows[0].rmse;
    st.counters["rmse_transmittance"] = r.rows[0].transmittance_rmse;
    st.counters["reference_s"] = r.reference_seconds;
    st.counters["fast_s"] = r.rows[0].seconds;
}

void BM_Fast960Ground(benchmark::State& st) { fast(st, scene(), 0, 960, 540); }
void BM_Fast960Inside(benchmark::State& st) { fast(st, scene(), 1, 960, 540); }
void BM_Fast960GroundGlow(benchmark::State& st) { fast(st, scene(), 0, 960, 540, true); }
void BM_SmokeGlow(benchmark::State& st) { fast(st, smoke_scene(), 0, 32, 18, true); }
void BM_ErrorGround240(benchmark::State& st) { error_vs_reference(st, scene(), 0, 240, 135); }
void BM_ErrorInside240(benchmark::State& st) { error_vs_reference(st, scene(), 1, 240, 135); }
void BM_SmokeFast(benchmark::State& st) { fast(st, smoke_scene(), 0, 32, 18); }
void BM_SmokeError(benchmark::State& st) { error_vs_reference(st, smoke_scene(), 1, 16, 9); }

} // namespace

BENCHMARK(BM_Fast960Ground)->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();
BENCHMARK(BM_Fast960Inside)->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();
BENCHMARK(BM_Fast960GroundGlow)->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();
BENCHMARK(BM_ErrorGround240)->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();
BENCHMARK(BM_ErrorInside240)->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();
BENCHMARK(BM_SmokeFast)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_SmokeError)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_SmokeGlow)->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();

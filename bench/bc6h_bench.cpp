// BC6H encoding throughput (texels/s) and error per quality. Data: a smooth 3-channel
// HDR modeling field (density-like [0,1], radiance-like: a sum of three 600 exp(-d/24)
// bumps, a height gradient). The target is Normal on 512x512x64 (16.8 M
// texels) in <= 30 s; the slab cases give texels/s for extrapolation
// (counter extrapolated_512x512x64_s). "Smoke" runs in well under 2 s for CI.
#include "atlas/compress/texture.h"

#include <benchmark/benchmark.h>

#include <cmath>
#include <ctime>

namespace {

using namespace atlas;
using namespace atlas::compress;

Field3D hdr_field(int nx, int ny, int nz) {
    Field3D f(Vec3i{{nx, ny, nz}}, 3, Box3d{{{0, 0, 0}}, {{nx * 8.0, ny * 8.0, nz * 8.0}}}, {"density", "radiance", "height"});
    for (int z = 0; z < nz; ++z)
        for (int y = 0; y < ny; ++y)
            for (int x = 0; x < nx; ++x) {
                const double s = std::sin(0.043 * x + 0.7) * std::sin(0.037 * y + 0.2) * std::cos(0.11 * z);
                double r = 0;
                for (int k = 0; k < 3; ++k) {
                    const double cx = nx * (0.25 + 0.25 * k), cy = ny * (0.3 + 0.2 * k), cz = nz * 0.5;
                    const double d = std::sqrt((x - cx) * (x - cx) + (y - cy) * (y - cy) + 16.0 * (z - cz) * (z - cz));
                    r += 600.0 * std::exp(-d / 24.0);
                }
                f.at(0, x, y, z) = float(std::clamp(0.5 + 0.5 * s, 0.0, 1.0));
                f.at(1, x, y, z) = float(r);
                f.at(2, x, y, z) = float(0.05 + 0.9 * double(z) / nz + 0.05 * std::sin(0.02 * (x + y)));
            }
    return f;
}

void run(benchmark::State& state, const Field3D& f, Format fmt, Quality q) {
    CompressOptions o;
    o.format = fmt;
    o.quality = q;
    CompressReport last;
    double cpu = 0;
    for (auto _ : state) {
        const std::clock_t c0 = std::clock(); // process CPU time, all threads
        EncodedTexture e = encode_texture(f, o);
        cpu = double(std::clock() - c0) / CLOCKS_PER_SEC;
        benchmark::DoNotOptimize(e.dds.data.data());
        last = e.report;
        state.SetIterationTime(e.report.encode_seconds);
    }
    state.counters["texels_per_s"] = last.texels_per_second;
    // CPU seconds of the whole call (encode + verification decode), all threads: on a
    // loaded shared machine, cpu_s / 2 estimates the wall time on 2 idle cores.
    state.counters["cpu_s"] = cpu;
    state.counters["cpu_512x512x64_s"] = cpu * 512.0 * 512.0 * 64.0 / double(last.texels);
    state.counters["extrapolated_512x512x64_s"] = last.texels_per_second > 0 ? 512.0 * 512.0 * 64.0 / last.texels_per_second : 0;
    for (size_t c = 0; c < last.max_error.size() && c < 3; ++c) {
        state.counters["max_err_c" + std::to_string(c)] = last.max_error[c];
        state.counters["rmse_c" + std::to_string(c)] = last.rmse[c];
    }
}

const Field3D& small() { static const Field3D f = hdr_field(32, 32, 4); return f; }
const Field3D& slab() { static const Field3D f = hdr_field(512, 512, 8); return f; }
const Field3D& mid() { static const Field3D f = hdr_field(128, 128, 8); return f; }
const Field3D& large() { static const Field3D f = hdr_field(512, 512, 64); return f; }

void Smoke_Bc6hNormal(benchmark::State& s) { run(s, small(), Format::Bc6hUf16, Quality::Normal); }
void Smoke_Bc6hSf16Normal(benchmark::State& s) { run(s, small(), Format::Bc6hSf16, Quality::Normal); }
void Bc6hFast_512x512x8(benchmark::State& s) { run(s, slab(), Format::Bc6hUf16, Quality::Fast); }
void Bc6hNormal_512x512x8(benchmark::State& s) { run(s, slab(), Format::Bc6hUf16, Quality::Normal); }
void Bc6hBest_128x128x8(benchmark::State& s) { run(s, mid(), Format::Bc6hUf16, Quality::Best); }
void Bc6hNormal_128x128x8(benchmark::State& s) { run(s, mid(), Format::Bc6hUf16, Quality::Normal); }
void Bc6hNormal_512x512x64(benchmark::State& s) { run(s, large(), Format::Bc6hUf16, Quality::Normal); }

} // namespace

BENCHMARK(Smoke_Bc6hNormal)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK(Smoke_Bc6hSf16Normal)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK(Bc6hFast_512x512x8)->UseManualTime()->Unit(benchmark::kSecond)->Iterations(1);
BENCHMARK(Bc6hNormal_512x512x8)->UseManualTime()->Unit(benchmark::kSecond)->Iterations(1);
BENCHMARK(Bc6hNormal_128x128x8)->UseManualTime()->Unit(benchmark::kSecond)->Iterations(1);
BENCHMARK(Bc6hBest_128x128x8)->UseManualTime()->Unit(benchmark::kSecond)->Iterations(1);
BENCHMARK(Bc6hNormal_512x512x64)->UseManualTime()->Unit(benchmark::kSecond)->Iterations(1);
BENCHMARK_MAIN();

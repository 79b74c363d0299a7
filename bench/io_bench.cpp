// io benchmarks: write and read one volume in each format. Sizes follow the
// design scale (4 channels of 128^3 noise; a 512x512x64 single-channel NVDF
// channel). Counters: bytes on disk and MB/s of field data (float32).
#include "atlas/core/hash.h"
#include "atlas/io/exr.h"
#include "atlas/io/tga_slices.h"
#include "atlas/io/vdb.h"

#include <benchmark/benchmark.h>

#include <cmath>
#include <filesystem>
#include <unistd.h>

namespace {
using namespace atlas;
namespace fs = std::filesystem;

fs::path bench_dir() {
    fs::path d = fs::temp_directory_path() / ("atlas_io_bench_" + std::to_string(::getpid()));
    fs::create_directories(d);
    return d;
}

// Smooth values in 0..1 with empty space (about half the voxels are 0), like a cloud.
Field3D cloudy(int n, int nz, int channels) {
    Field3D f({{n, n, nz}}, channels, Box3d{{{0, 0, 0}}, {{double(n) * 8, double(n) * 8, double(nz) * 8}}});
    for (int c = 0; c < channels; ++c)
        for (int z = 0; z < nz; ++z)
            for (int y = 0; y < n; ++y)
                for (int x = 0; x < n; ++x) {
                    const double s = std::sin(x * 0.11 + c) * std::cos(y * 0.07) + std::sin(z * 0.13);
                    f.at(c, x, y, z) = s > 0 ? float(std::min(1.0, s)) : 0.0f;
                }
    return f;
}

uint64_t dir_bytes(const fs::path& d) {
    uint64_t b = 0;
    for (const auto& e : fs::directory_iterator(d)) b += fs::file_size(e.path());
    return b;
}

template <typename Write, typename Read>
void run(benchmark::State& state, const Field3D& f, Write&& write, Read&& read, bool do_read) {
    const fs::path d = bench_dir() / std::to_string(state.thread_index());
    fs::remove_all(d);
    fs::create_directories(d);
    write(d);
    for (auto _ : state) {
        if (do_read) benchmark::DoNotOptimize(read(d));
        else write(d);
    }
    state.counters["disk_MB"] = double(dir_bytes(d)) / 1e6;
    state.SetBytesProcessed(int64_t(state.iterations()) * int64_t(f.byte_size()));
    fs::remove_all(d);
    std::error_code ec;
    fs::remove(d.parent_path(), ec); // only when empty
}

void exr(benchmark::State& state, int n, int nz, int ch, bool half, bool read) {
    const Field3D f = cloudy(n, nz, ch);
    io::ExrOptions o;
    o.half = half;
    run(state, f, [&](const fs::path& d) { io::write_exr(f, d / "f.exr", o); }, [&](const fs::path& d) { return io::read_exr(d / "f.exr"); }, read);
}

void vdb(benchmark::State& state, int n, int nz, int ch, bool read) {
    const Field3D f = cloudy(n, nz, ch);
    run(state, f, [&](const fs::path& d) { io::write_vdb(f, d / "f.vdb"); }, [&](const fs::path& d) { return io::read_vdb(d / "f.vdb"); }, read);
}

void slices(benchmark::State& state, int n, int nz, int ch, bool read) {
    const Field3D f = cloudy(n, nz, ch);
    run(state, f, [&](const fs::path& d) { io::write_tga_slices(f, d, "s"); },
        [&](const fs::path& d) { return io::read_tga_slices(d / "s.001.tga", f.bounds(), ch); }, read);
}

} // namespace

// Tiny versions for the ctest smoke run.
BENCHMARK_CAPTURE(exr, Smoke_write_16, 16, 16, 1, false, false);
BENCHMARK_CAPTURE(vdb, Smoke_write_16, 16, 16, 1, false);
BENCHMARK_CAPTURE(slices, Smoke_write_16, 16, 16, 1, false);

// The Nubis noise volume: 4 channels of 128^3.
BENCHMARK_CAPTURE(exr, write_noise_128x4, 128, 128, 4, false, false)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(exr, read_noise_128x4, 128, 128, 4, false, true)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(exr, write_half_noise_128x4, 128, 128, 4, true, false)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(vdb, write_noise_128x4, 128, 128, 4, false)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(vdb, read_noise_128x4, 128, 128, 4, true)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(slices, write_noise_128x4, 128, 128, 4, false)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(slices, read_noise_128x4, 128, 128, 4, true)->Unit(benchmark::kMillisecond);
// One channel of the design-scale cloudscape: 512x512x64.
BENCHMARK_CAPTURE(exr, write_cloudscape_512x64, 512, 64, 1, false, false)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(vdb, write_cloudscape_512x64, 512, 64, 1, false)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(vdb, read_cloudscape_512x64, 512, 64, 1, true)->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();

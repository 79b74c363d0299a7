// Compression throughput (texels/s) per format and quality, with the error reached.
// Large cases use the design's 512x512x64 volume (16.8 M texels) of SDF-like data;
// "Smoke" cases are tiny (ctest runs them).
#include "sdf_volume.h"
#include "atlas/compress/texture.h"

#include <benchmark/benchmark.h>

#include <cmath>

namespace {

using namespace atlas;
using namespace atlas::compress;

using atlas::bench::sdf_volume;

Field3D rgb_volume(int nx, int ny, int nz) {
    Field3D f(Vec3i{{nx, ny, nz}}, 3, Box3d{{{0, 0, 0}}, {{1, 1, 1}}});
    for (int z = 0; z < nz; ++z)
        for (int y = 0; y < ny; ++y)
            for (int x = 0; x < nx; ++x)
                for (int c = 0; c < 3; ++c)
                    f.at(c, x, y, z) = float(0.5 + 0.4 * std::sin(0.05 * x * (c + 1) + 0.031 * y + 0.2 * z + c));
    return f;
}

void run(benchmark::State& state, const Field3D& f, Format fmt, Quality q, bool one_sided, DecoderSet decoders,
         double max_error = -1) {
    CompressOptions o;
    if (max_error >= 0) o.max_error = max_error; // encode_texture reports misses, it does not throw
    o.format = fmt;
    o.quality = q;
    o.one_sided_below = one_sided;
    o.decoders = decoders;
    CompressReport last;
    for (auto _ : state) {
        EncodedTexture e = encode_texture(f, o);
        benchmark::DoNotOptimize(e.dds.data.data());
        last = e.report;
        state.SetIterationTime(e.report.encode_seconds);
    }
    state.counters["texels_per_s"] = last.texels_per_second;
    state.counters["max_err_m"] = last.bound_max_error;
    state.counters["rmse_m"] = last.rmse.empty() ? 0 : last.rmse[0];
    state.counters["mean_under_m"] = last.per_decoder.empty() ? 0 : last.per_decoder[0].mean_under;
    state.counters["blocks_over_bound"] = double(last.blocks_over_bound.size());
}

const Field3D& sdf_small() { static const Field3D f = sdf_volume(32, 32, 4); return f; }
const Field3D& sdf_large() { static const Field3D f = sdf_volume(512, 512, 64); return f; }
const Field3D& sdf_mid() { static const Field3D f = sdf_volume(128, 128, 32); return f; }
const Field3D& rgb_small() { static const Field3D f = rgb_volume(32, 32, 4); return f; }
const Field3D& rgb_mid() { static const Field3D f = rgb_volume(256, 256, 8); return f; }

// A whole small texture, the encoder's set-up included: what every small DDS output and
// every tile pays (issue 49: the BC4 tables were built again for each texture).
void per_texture(benchmark::State& state, DecoderSet decoders) {
    static const Field3D f = sdf_volume(64, 64, 1);
    CompressOptions o;
    o.format = Format::Bc4;
    o.decoders = decoders;
    for (auto _ : state) {
        EncodedTexture e = encode_texture(f, o);
        benchmark::DoNotOptimize(e.dds.data.data());
    }
}
void Bc4PerTexture_64x64_Reference(benchmark::State& s) { per_texture(s, kReferenceOnly); }
void Bc4PerTexture_64x64_AllDecoders(benchmark::State& s) { per_texture(s, kAllDecoders); }

void Smoke_Bc4(benchmark::State& s) { run(s, sdf_small(), Format::Bc4, Quality::Normal, false, kAllDecoders); }
void Smoke_Bc1Scalar(benchmark::State& s) { run(s, sdf_small(), Format::Bc1Scalar, Quality::Normal, true, kAllDecoders); }
void Smoke_Bc1(benchmark::State& s) { run(s, rgb_small(), Format::Bc1, Quality::Normal, false, kAllDecoders); }

void Bc4Normal_512x512x64(benchmark::State& s) { run(s, sdf_large(), Format::Bc4, Quality::Normal, false, kAllDecoders); }
void Bc4NormalOneSided_512x512x64(benchmark::State& s) { run(s, sdf_large(), Format::Bc4, Quality::Normal, true, kAllDecoders); }
void Bc4Fast_512x512x64(benchmark::State& s) { run(s, sdf_large(), Format::Bc4, Quality::Fast, false, kAllDecoders); }
void Bc1ScalarOneSided_512x512x64(benchmark::State& s) { run(s, sdf_large(), Format::Bc1Scalar, Quality::Normal, true, kAllDecoders); }
void Bc1ScalarOneSidedReference_512x512x64(benchmark::State& s) { run(s, sdf_large(), Format::Bc1Scalar, Quality::Normal, true, kReferenceOnly); }
// The decoder set graphs/cloudscape.yaml writes its field data for (8-bit decoders disagree).
constexpr DecoderSet kFieldDataSet = kReferenceOnly | decoder_bit(Decoder::Nvidia) | decoder_bit(Decoder::Amd);
void Bc1ScalarOneSidedFieldDataSet_512x512x64(benchmark::State& s) { run(s, sdf_large(), Format::Bc1Scalar, Quality::Normal, true, kFieldDataSet); }
void Bc1ScalarOneSidedFieldDataSetBest_128x128x32(benchmark::State& s) { run(s, sdf_mid(), Format::Bc1Scalar, Quality::Best, true, kFieldDataSet); }
void Bc4OneSidedReference_512x512x64(benchmark::State& s) { run(s, sdf_large(), Format::Bc4, Quality::Normal, true, kReferenceOnly); }
// Every block misses 0.01 m and falls back to the exhaustive BC4 search.
void Bc4BoundedFallback_128x128x32(benchmark::State& s) { run(s, sdf_mid(), Format::Bc4, Quality::Normal, false, kAllDecoders, 0.01); }
void Bc4Best_128x128x32(benchmark::State& s) { run(s, sdf_mid(), Format::Bc4, Quality::Best, false, kAllDecoders); }
void Bc1Normal_256x256x8(benchmark::State& s) { run(s, rgb_mid(), Format::Bc1, Quality::Normal, false, kAllDecoders); }
void Bc1Fast_256x256x8(benchmark::State& s) { run(s, rgb_mid(), Format::Bc1, Quality::Fast, false, kAllDecoders); }

} // namespace

BENCHMARK(Smoke_Bc4)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK(Bc4PerTexture_64x64_Reference)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime();
BENCHMARK(Bc4PerTexture_64x64_AllDecoders)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime();
BENCHMARK(Smoke_Bc1Scalar)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK(Smoke_Bc1)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK(Bc4Fast_512x512x64)->UseManualTime()->Unit(benchmark::kSecond)->Iterations(1);
BENCHMARK(Bc4Normal_512x512x64)->UseManualTime()->Unit(benchmark::kSecond)->Iterations(1);
BENCHMARK(Bc4NormalOneSided_512x512x64)->UseManualTime()->Unit(benchmark::kSecond)->Iterations(1);
BENCHMARK(Bc4OneSidedReference_512x512x64)->UseManualTime()->Unit(benchmark::kSecond)->Iterations(1);
BENCHMARK(Bc1ScalarOneSided_512x512x64)->UseManualTime()->Unit(benchmark::kSecond)->Iterations(1);
BENCHMARK(Bc1ScalarOneSidedReference_512x512x64)->UseManualTime()->Unit(benchmark::kSecond)->Iterations(1);
BENCHMARK(Bc1ScalarOneSidedFieldDataSet_512x512x64)->UseManualTime()->Unit(benchmark::kSecond)->Iterations(1);
BENCHMARK(Bc1ScalarOneSidedFieldDataSetBest_128x128x32)->UseManualTime()->Unit(benchmark::kSecond)->Iterations(1);
BENCHMARK(Bc4BoundedFallback_128x128x32)->UseManualTime()->Unit(benchmark::kSecond)->Iterations(1);
BENCHMARK(Bc4Best_128x128x32)->UseManualTime()->Unit(benchmark::kSecond)->Iterations(1);
BENCHMARK(Bc1Fast_256x256x8)->UseManualTime()->Unit(benchmark::kSecond)->Iterations(1);
BENCHMARK(Bc1Normal_256x256x8)->UseManualTime()->Unit(benchmark::kSecond)->Iterations(1);
BENCHMARK_MAIN();

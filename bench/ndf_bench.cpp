// NDF benchmarks: the hzd_weather.yaml recipe as library calls at N x N, and
// cone maps (max-mip branch and bound vs brute force).
#include "atlas/ndf/cone_map.h"
#include "atlas/ndf/generators.h"
#include "atlas/ndf/ndf_set.h"
#include "atlas/ndf/operators.h"

#include "atlas/core/field_math.h"

#include <benchmark/benchmark.h>

#include <algorithm>

namespace {
using namespace atlas;
using namespace atlas::ndf;

// The recipe of graphs/hzd_weather.yaml (same nodes, same parameters). Values
// move into shared pointers as the graph hands them on (no extra copies).
Field2D hzd_weather(int n) {
    const Vec2i res{{n, n}};
    const Box2d box{{{0, 0}}, {{60000, 60000}}};
    Field2D cov_noise = noise2d(res, box, {{6, 6}}, 5, 0.55, 11, nullptr);
    Field2D warp_noise = noise2d(res, box, {{3, 3}}, 2, 0.5, 12, nullptr);
    Field2D warped = domain_warp(cov_noise, warp_noise, 2500, WrapMode::Wrap, nullptr);
    Field2D coverage = apply_curve(warped, Curve::parse("0 0; 0.35 0.05; 0.55 0.55; 0.75 0.9; 1 1"), nullptr);
    Field2D type_noise = noise2d(res, box, {{2, 2}}, 3, 0.5, 21, nullptr);
    Value type = field_remap(Field2DPtr(std::make_shared<Field2D>(std::move(type_noise))), 0.2, 0.8, 0, 0.67, true, nullptr);
    Field2D drizzle = threshold(noise2d(res, box, {{4, 4}}, 3, 0.5, 31, nullptr), 0.7, 0.2, nullptr);
    Value light = field_remap(Field2DPtr(std::make_shared<Field2D>(std::move(drizzle))), 0, 1, 0, 0.4, true, nullptr);
    Field2D storm = paint_shapes(res, box, parse_shapes("ellipse 40000 22000 9000 6000 1.0 6000; stroke 3000 0.8 3000 30000 30000 42000 34000 52000 30000"), nullptr);
    Field2D precip = composite(*std::get<Field2DPtr>(light), storm, nullptr, CompositeOp::Max, 1.0, nullptr);
    Field2D set = make_ndf_set(res, box, 1500, 4000, nullptr);
    auto copy = [&](int c, const Field2D& f) { std::copy(f.channel(0).begin(), f.channel(0).end(), set.channel(c).begin()); };
    copy(Coverage, coverage);
    const Field2D& t = *std::get<Field2DPtr>(type);
    copy(Type, t);
    copy(TopType, t);
    copy(BottomType, t);
    copy(Precipitation, precip);
    return apply_precipitation_rule(set, PrecipitationRule{}, nullptr);
}

void BM_HzdWeatherSet(benchmark::State& state) {
    for (auto _ : state) benchmark::DoNotOptimize(hzd_weather(int(state.range(0))));
    state.SetLabel(std::to_string(state.range(0)) + "^2 NDF set");
}
BENCHMARK(BM_HzdWeatherSet)->Arg(2048)->Unit(benchmark::kMillisecond)->MinTime(2.0);
void BM_HzdWeatherSetSmoke(benchmark::State& state) {
    for (auto _ : state) benchmark::DoNotOptimize(hzd_weather(32));
}
BENCHMARK(BM_HzdWeatherSetSmoke);

// The recipe's stages one by one at 2048^2 (which node dominates).
void BM_Stage(benchmark::State& state) {
    const int n = 2048;
    const Vec2i res{{n, n}};
    const Box2d box{{{0, 0}}, {{60000, 60000}}};
    const Field2D a = noise2d(res, box, {{6, 6}}, 5, 0.55, 11, nullptr);
    const Field2D b = noise2d(res, box, {{3, 3}}, 2, 0.5, 12, nullptr);
    const auto shapes = parse_shapes("ellipse 40000 22000 9000 6000 1.0 6000; stroke 3000 0.8 3000 30000 30000 42000 34000 52000 30000");
    const Curve curve = Curve::parse("0 0; 0.35 0.05; 0.55 0.55; 0.75 0.9; 1 1");
    Field2D set = make_ndf_set(res, box, 1500, 4000, nullptr);
    for (auto _ : state) {
        switch (state.range(0)) {
        case 0: benchmark::DoNotOptimize(noise2d(res, box, {{6, 6}}, 5, 0.55, 11, nullptr)); break;
        case 1: benchmark::DoNotOptimize(domain_warp(a, b, 2500, WrapMode::Wrap, nullptr)); break;
        case 2: benchmark::DoNotOptimize(paint_shapes(res, box, shapes, nullptr)); break;
        case 3: benchmark::DoNotOptimize(apply_curve(a, curve, nullptr)); break;
        case 4: benchmark::DoNotOptimize(threshold(a, 0.7, 0.2, nullptr)); break;
        case 5: benchmark::DoNotOptimize(composite(a, b, nullptr, CompositeOp::Max, 1.0, nullptr)); break;
        case 6: benchmark::DoNotOptimize(make_ndf_set(res, box, 1500, 4000, nullptr)); break;
        case 7: benchmark::DoNotOptimize(apply_precipitation_rule(set, PrecipitationRule{}, nullptr)); break;
        case 8: benchmark::DoNotOptimize(blur(a, 4, WrapMode::Wrap, nullptr)); break;
        }
    }
    static const char* const names[] = {"noise 5 oct", "warp", "shapes", "curve", "threshold", "composite", "set alloc", "rain rule", "blur sigma 4"};
    state.SetLabel(names[state.range(0)]);
}
BENCHMARK(BM_Stage)->DenseRange(0, 8)->Unit(benchmark::kMillisecond);

Field2D heights(int n) {
    // A smooth envelope top: the weather recipe's coverage as max height.
    Field2D c = noise2d({{n, n}}, {{{0, 0}}, {{double(n), double(n)}}}, {{4, 4}}, 4, 0.5, 5, nullptr);
    for (float& v : c.channel(0)) v = 1500.0f + 2500.0f * v; // metres, texel = 1 m: steep
    return c;
}

void BM_ConeMapPyramid(benchmark::State& state) {
    const Field2D h = heights(int(state.range(0)));
    ConeMapOptions opt;
    opt.robust = state.range(1) != 0;
    opt.texel_size = 60000.0 / double(state.range(0)); // a 60 km map
    for (auto _ : state) benchmark::DoNotOptimize(cone_map(h, 0, opt, nullptr));
}
BENCHMARK(BM_ConeMapPyramid)->Args({64, 1})->Args({128, 1})->Args({256, 1})->Args({1024, 1})->Args({1024, 0})->Unit(benchmark::kMillisecond);

void BM_ConeMapBruteForce(benchmark::State& state) {
    const Field2D h = heights(int(state.range(0)));
    ConeMapOptions opt;
    opt.robust = true;
    opt.texel_size = 60000.0 / double(state.range(0));
    for (auto _ : state) benchmark::DoNotOptimize(cone_map_brute_force(h, 0, opt, nullptr));
}
BENCHMARK(BM_ConeMapBruteForce)->Arg(64)->Arg(128)->Arg(256)->Unit(benchmark::kMillisecond);

void BM_ConeMapSmoke(benchmark::State& state) {
    const Field2D h = heights(16);
    for (auto _ : state) benchmark::DoNotOptimize(cone_map(h, 0, ConeMapOptions{}, nullptr));
}
BENCHMARK(BM_ConeMapSmoke);
} // namespace

BENCHMARK_MAIN();

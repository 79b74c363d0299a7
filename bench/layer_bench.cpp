// 2.5D layer renderer benchmarks (atlas/render/layer.h): 960x540 ground and
// aerial views of graphs/superstorm.yaml's NDF set (cooked through the graph
// API, outside the timing) with the HZD noise set (128^3, 32^3, 128^2) and
// the default profile LUT; the aerial view with and without the envelope's
// cone map over the cloud tops (the speed-up), with the image difference.
// Smoke variants are tiny and only prove the code runs.
#include "atlas/graph/evaluator.h"
#include "atlas/ndf/cone_map.h"
#include "atlas/ndf/ndf_set.h"
#include "atlas/ndf/vertical_profile.h"
#include "atlas/noise/recipes.h"
#include "atlas/render/layer.h"

#include <benchmark/benchmark.h>

#include <sys/resource.h>

#include <cmath>
#include <memory>

namespace {
using namespace atlas;
using namespace atlas::render;

double process_cpu_seconds() {
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    return double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) + 1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

LayerScene with_noise(Field2DPtr set, int low, int high) {
    LayerScene s;
    s.ndf = std::move(set);
    s.profile_lut = std::make_shared<const Field2D>(ndf::build_profile_lut(ndf::VerticalProfile{}, 97, 128, nullptr));
    noise::HzdNoise n = noise::make_hzd_noise(low, high, low, 0);
    s.base_noise = std::make_shared<const Field3D>(std::move(n.low));
    s.detail_noise = std::make_shared<const Field3D>(std::move(n.high));
    s.curl = std::make_shared<const Field2D>(std::move(n.curl));
    return s;
}

// The cone map atlas preview builds (cmd_preview.cpp, cloud_top_cone_map):
// tops max-pooled to <= 128 texels a side, dilated by one, robust cones.
Field2DPtr top_cone_map(const Field2D& set) {
    const int cc = set.find_channel("coverage"), cm = set.find_channel("max_height");
    const int w = set.width(), h = set.height(), k = std::max(1, (std::max(w, h) + 127) / 128);
    const int pw = (w + k - 1) / k, ph = (h + k - 1) / k;
    Field2D pooled({{pw, ph}}, 1, set.bounds()), tops({{pw, ph}}, 1, set.bounds());
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            if (set.at(cc, x, y) > 0) pooled.at(0, x / k, y / k) = std::max(pooled.at(0, x / k, y / k), set.at(cm, x, y));
    for (int y = 0; y < ph; ++y)
        for (int x = 0; x < pw; ++x)
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx)
                    tops.at(0, x, y) = std::max(tops.at(0, x, y), pooled.at(0, std::clamp(x + dx, 0, pw - 1), std::clamp(y + dy, 0, ph - 1)));
    ndf::ConeMapOptions o;
    o.robust = true;
    o.texel_size = std::min((set.bounds().max[0] - set.bounds().min[0]) / pw, (set.bounds().max[1] - set.bounds().min[1]) / ph);
    return std::make_shared<const Field2D>(ndf::cone_map(tops, 0, o, nullptr));
}

const LayerScene& superstorm() {
    static const LayerScene s = [] {
        Session session(builtin_nodes());
        session.load(std::string(ATLAS_SOURCE_DIR) + "/graphs/superstorm.yaml");
        CookOptions o;
        o.write_outputs = false;
        LayerScene l = with_noise(std::get<Field2DPtr>(session.get("mesocyclone", "out", o)), 128, 32);
        l.edge = MapEdge::Empty; // as atlas preview does for a superstorm set
        return l;
    }();
    return s;
}

const LayerScene& smoke_scene() {
    static const LayerScene s = [] {
        Field2D set = ndf::make_ndf_set({{8, 8}}, Box2d{{{0, 0}}, {{8000, 8000}}}, 1500, 3500, nullptr);
        for (int y = 0; y < 8; ++y)
            for (int x = 0; x < 8; ++x) set.at(ndf::Coverage, x, y) = 0.6f;
        return with_noise(std::make_shared<const Field2D>(std::move(set)), 16, 8);
    }();
    return s;
}

RenderSettings settings_for(const LayerScene& s, LayerView v, int w, int h) {
    RenderSettings st;
    st.width = w;
    st.height = h;
    st.camera = layer_camera(s, v, double(w) / h);
    st.sky_colour = {{0.07f, 0.17f, 0.50f}};
    st.sky_horizon = Vec3f{{0.45f, 0.55f, 0.70f}};
    st.sun_direction = sun_direction(230, 20);
    st.sun_colour = {{2.6f, 2.45f, 2.25f}};
    return st;
}

void run(benchmark::State& st, const LayerScene& scene, const RenderSettings& s) {
    const double cpu0 = process_cpu_seconds();
    LayerReport rep;
    for (auto _ : st) {
        auto r = render_layer(scene, s, nullptr);
        rep = r.report;
        benchmark::DoNotOptimize(r.image.channel(0).data());
    }
    st.counters["cheap_samples"] = double(rep.cheap_samples);
    st.counters["full_samples"] = double(rep.full_samples);
    st.counters["skipped_steps"] = double(rep.skipped_steps);
    st.counters["process_cpu_s"] = (process_cpu_seconds() - cpu0) / double(st.iterations());
}

void BM_LayerGround960(benchmark::State& st) { run(st, superstorm(), settings_for(superstorm(), LayerView::Ground, 960, 540)); }
void BM_LayerAerial960Plain(benchmark::State& st) { run(st, superstorm(), settings_for(superstorm(), LayerView::Aerial, 960, 540)); }
void BM_LayerAerial960Cone(benchmark::State& st) {
    LayerScene s = superstorm();
    const double t0 = process_cpu_seconds();
    s.envelope.cone_map = top_cone_map(*s.ndf);
    st.counters["cone_map_cpu_s"] = process_cpu_seconds() - t0;
    const RenderSettings rs = settings_for(s, LayerView::Aerial, 960, 540);
    run(st, s, rs);
    // Image error of each against a quality-3 plain reference (transmittance):
    // the step placement itself is noisy at preview steps, so skipping is
    // judged by whether it adds error, not by equality with one plain march.
    RenderSettings ref_s = rs;
    ref_s.quality = 3;
    const auto ref = render_layer(superstorm(), ref_s, nullptr);
    const auto a = render_layer(superstorm(), rs, nullptr), b = render_layer(s, rs, nullptr);
    auto rmse = [&](const Field2D& x, const Field2D& y) {
        double se = 0;
        for (int j = 0; j < rs.height; ++j)
            for (int i = 0; i < rs.width; ++i) {
                const double d = double(x.at(3, i, j)) - y.at(3, i, j);
                se += d * d;
            }
        return std::sqrt(se / (double(rs.width) * rs.height));
    };
    st.counters["rmse_T_plain_vs_ref"] = rmse(a.image, ref.image);
    st.counters["rmse_T_cone_vs_ref"] = rmse(b.image, ref.image);
    st.counters["rmse_T_cone_vs_plain"] = rmse(a.image, b.image);
}
void BM_SmokeLayer(benchmark::State& st) { run(st, smoke_scene(), settings_for(smoke_scene(), LayerView::Ground, 32, 18)); }

} // namespace

BENCHMARK(BM_LayerGround960)->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();
BENCHMARK(BM_LayerAerial960Plain)->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();
BENCHMARK(BM_LayerAerial960Cone)->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();
BENCHMARK(BM_SmokeLayer)->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();

// The ndf nodes through the graph engine: library results, export layouts, warnings and errors.
#include "atlas/core/error.h"
#include "atlas/graph/evaluator.h"
#include "atlas/graph/node.h"
#include "atlas/ndf/generators.h"
#include "atlas/ndf/ndf_set.h"
#include "atlas/ndf/superstorm.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>

using namespace atlas;

namespace {
const char* kGraph = R"(atlas: 1
nodes:
  cov:
    type: ndf/noise
    params: {resolution: [48, 40], bounds_max: [6000, 5000], period: [3, 2], octaves: 2, seed: 4}
  rain:
    type: ndf/gradient
    params: {resolution: [48, 40], bounds_max: [6000, 5000], mode: linear, start: [0, 0], end: [6000, 0]}
  set:
    type: ndf/set
    inputs: {coverage: cov, precipitation: rain}
    params: {type: 0.3, min_height: 1000, max_height: 5000}
  weather:
    type: ndf/precipitation_rule
    inputs: {in: set}
  storm:
    type: ndf/superstorm
    inputs: {in: weather}
    params: {center: [3000, 2500], radius: 1500}
  far_storm:
    type: ndf/superstorm
    inputs: {in: weather}
    params: {center: [90000, 2500], radius: 1500}
  unity:
    type: ndf/unity_cloud_map
    inputs: {in: storm}
    params: {layer_bottom: 0, layer_top: 10000}
  lut:
    type: ndf/profile_lut
    params: {resolution: [16, 32]}
outputs:
  - {node: unity, file: unity.png}
  - {node: far_storm, file: far.exr}
)";
template <typename T>
std::shared_ptr<const T> as(const Value& v) {
    return std::get<std::shared_ptr<const T>>(v);
}
} // namespace

TEST(NdfNodes, GraphMatchesLibraryAndLayouts) {
    Session s(builtin_nodes());
    s.load_text(kGraph, "ndf_nodes.yaml", std::filesystem::temp_directory_path());
    CookOptions co;
    co.write_outputs = false;
    const Box2d box{{{0, 0}}, {{6000, 5000}}};
    Field2D set = ndf::make_ndf_set({{48, 40}}, box, 1000, 5000, nullptr);
    const Field2D cov = ndf::noise2d({{48, 40}}, box, {{3, 2}}, 2, 0.5, 4, nullptr);
    const Field2D rain = ndf::gradient_linear({{48, 40}}, box, {{0, 0}}, {{6000, 0}}, nullptr);
    for (size_t i = 0; i < set.voxel_count(); ++i) {
        set.channel(ndf::Coverage)[i] = cov.channel(0)[i];
        set.channel(ndf::Precipitation)[i] = rain.channel(0)[i];
        set.channel(ndf::Type)[i] = set.channel(ndf::TopType)[i] = set.channel(ndf::BottomType)[i] = 0.3f;
    }
    const Field2D weather = ndf::apply_precipitation_rule(set, {}, nullptr);
    EXPECT_TRUE(*as<Field2D>(s.get("weather", "out", co)) == weather);
    ndf::SuperstormStencil st;
    st.center = {{3000, 2500}};
    st.radius = 1500;
    const Field2D storm = ndf::apply_superstorm(weather, st, nullptr);
    EXPECT_TRUE(*as<Field2D>(s.get("storm", "out", co)) == storm);
    auto unity = as<Field2D>(s.get("unity", "out", co));
    ASSERT_EQ(unity->channels(), 4);
    for (size_t i = 0; i < storm.voxel_count(); ++i) {
        ASSERT_EQ(unity->channel(0)[i], storm.channel(ndf::Coverage)[i]);
        ASSERT_EQ(unity->channel(1)[i], storm.channel(ndf::Precipitation)[i]);
        ASSERT_EQ(unity->channel(2)[i], storm.channel(ndf::Type)[i]);
        ASSERT_FLOAT_EQ(unity->channel(3)[i], std::clamp(storm.channel(ndf::MaxHeight)[i] / 10000.0f, 0.0f, 1.0f));
    }
    const CookResult r = s.cook([&] { CookOptions c = co; c.outputs = {"far.exr"}; return c; }());
    ASSERT_FALSE(r.nodes.at("far_storm").warnings.empty()); // entirely outside the map
    EXPECT_TRUE(*as<Field2D>(s.get("far_storm", "out", co)) == weather);
    Session lut_session(builtin_nodes());
    lut_session.load_text(R"(atlas: 1
nodes:
  lut: {type: ndf/profile_lut, params: {resolution: [16, 32]}}
outputs:
  - {node: lut, file: lut.exr}
)", "lut.yaml", std::filesystem::temp_directory_path());
    const CookResult lr = lut_session.cook(co);
    ASSERT_TRUE(lr.nodes.at("lut").metrics.count("max_error"));
    EXPECT_GT(lr.nodes.at("lut").metrics.at("max_error"), 0.0);
    EXPECT_LT(lr.nodes.at("lut").metrics.at("max_error"), 0.2);
}

TEST(NdfNodes, ClearErrors) {
    struct Case {
        const char *node, *port, *names;
    };
    for (const Case& c : {Case{"{type: ndf/superstorm, inputs: {in: s}, params: {radius: 0}}", "out", "radius"},
                          Case{"{type: ndf/superstorm, inputs: {in: s}, params: {min_height: 9000, max_height: 100}}", "out", "min_height"},
                          Case{"{type: ndf/vortex_rings, params: {rings: 3, ring_radii: '100 50 200'}}", "map", "ring_radii"}}) {
        Session s(builtin_nodes());
        const std::string g = std::string("atlas: 1\nnodes:\n  s: {type: ndf/set, params: {resolution: [8, 8]}}\n  x: ") + c.node +
                              "\noutputs:\n  - {node: x, port: " + c.port + ", file: x.exr}\n";
        CookOptions co;
        co.write_outputs = false;
        try { // a range the declaration states is refused when the graph loads, others when cooking
            s.load_text(g, "bad.yaml", std::filesystem::temp_directory_path());
            s.cook(co);
            ADD_FAILURE() << "no error for " << c.node;
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find(c.names), std::string::npos) << e.what();
        }
    }
}

namespace {
std::string read_text(const std::filesystem::path& p) {
    std::FILE* f = std::fopen(p.string().c_str(), "rb");
    if (!f) return {};
    std::string s;
    char buf[4096];
    size_t n;
    while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) s.append(buf, n);
    std::fclose(f);
    return s;
}
} // namespace

TEST(NdfGraphs, HzdWeatherShowsTheRainRule) {
    const std::filesystem::path dir = std::filesystem::path(ATLAS_SOURCE_DIR) / "graphs";
    Session s(builtin_nodes());
    s.load_text(read_text(dir / "hzd_weather.yaml"), "hzd_weather.yaml", dir);
    CookOptions co;
    co.write_outputs = false;
    auto w = as<Field2D>(s.get("weather", "out", co));
    ndf::check_ndf_set(*w);
    size_t certain = 0;
    for (size_t i = 0; i < w->voxel_count(); ++i)
        if (w->channel(ndf::Precipitation)[i] >= 1.0f) {
            ++certain;
            ASSERT_EQ(w->channel(ndf::Type)[i], 1.0f);
            ASSERT_GE(w->channel(ndf::Coverage)[i], 0.7f);
        }
    EXPECT_GT(certain, 1000u); // the storm region exists
    auto unity = as<Field2D>(s.get("unity_map", "out", co));
    EXPECT_EQ(unity->channels(), 4);
    for (const char* g : {"superstorm.yaml", "envelope_mountain.yaml"}) {
        Session other(builtin_nodes());
        other.load_text(read_text(dir / g), g, dir);
        EXPECT_NO_THROW(other.cook(co)) << g;
    }
}

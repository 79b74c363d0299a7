// The sim nodes through the graph engine, against the library run directly
// (an independent reference: the same set-up written out by hand), plus the
// 'vdb-sequence' output format read back with io::read_vdb.
#include "atlas/core/error.h"
#include "atlas/graph/evaluator.h"
#include "atlas/graph/node.h"
#include "atlas/io/vdb.h"
#include "atlas/io/writers.h"
#include "atlas/sim/simulation.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <mutex>

using namespace atlas;
namespace fs = std::filesystem;

namespace {

// A sounding saturated below the inversion and a warm bubble: cloud forms in a few steps.
const char* kGraph = R"(atlas: 1
nodes:
  air:
    type: sim/sounding
    params: {theta_lapse: 0.002, inversion_height: 500, inversion_jump: 3, surface_rh: 1, rh_lapse: 0, rh_above: 0.5}
  patch:
    type: sim/emitter
    params: {resolution: [16, 16, 4], bounds_max: [640, 640, 160], center: [320, 320], radius: 200, depth: 120,
             heat_rate: 0.05, vapour_rate: 5e-6, noise_amount: 0.5, seed: 3}
  cloud:
    type: sim/cloud_growth
    inputs: {sounding: air.out, emitter: patch}
    params: {resolution: [16, 16, 16], dx: 40, duration: 40, frame_dt: 10, pressure_tolerance: 1e-7,
             bubble_theta: 2, bubble_center: [320, 320, 150], bubble_radius: 150,
             sequence_every: 2, sequence_grids: "density, vel"}
outputs:
  - {node: cloud, port: sequence, file: seq/cloud, format: vdb-sequence}
  - {node: cloud, port: out, file: final.vdb}
)";

template <typename T>
std::shared_ptr<const T> as(const Value& v) {
    return std::get<std::shared_ptr<const T>>(v);
}

CookOptions values_only() {
    CookOptions co;
    co.write_outputs = false;
    co.jobs = 1;
    return co;
}

// The graph's sounding as the node sends it: the record holds floats, so each
// member is the float nearest the graph's value.
sim::Sounding graph_sounding() {
    auto f = [](double v) { return double(float(v)); };
    sim::Sounding s;
    s.surface_pressure = f(1e5);
    s.surface_theta = f(300);
    s.theta_lapse = f(0.002);
    s.inversion_height = f(500);
    s.inversion_jump = f(3);
    s.inversion_depth = f(200);
    s.theta_lapse_above = f(0.004); // sim/sounding default
    s.surface_rh = f(1.0);
    s.rh_lapse = 0;
    s.rh_above = f(0.5);
    return s;
}

fs::path temp_dir(const std::string& tag) {
    const fs::path d = fs::temp_directory_path() / ("atlas_simnodes_" + tag + "_" + std::to_string(::getpid()));
    fs::remove_all(d);
    fs::create_directories(d);
    return d;
}

std::string error_of(Session& s, const std::string& node, const std::string& port, const CookOptions& co = values_only()) {
    try {
        s.get(node, port, co);
    } catch (const Error& e) {
        return e.what();
    }
    return "";
}

} // namespace

TEST(SimNodes, SoundingRecordAndProfileMatchTheLibrary) {
    Session s(builtin_nodes());
    s.load_text(kGraph, "sim.yaml", fs::temp_directory_path());
    const auto rec = as<Field2D>(s.get("air", "out", values_only()));
    ASSERT_EQ(rec->width(), 1);
    const sim::Sounding want = graph_sounding();
    EXPECT_FLOAT_EQ(rec->channel(rec->find_channel("theta_lapse"))[0], float(want.theta_lapse));
    EXPECT_FLOAT_EQ(rec->channel(rec->find_channel("inversion_height"))[0], float(want.inversion_height));
    EXPECT_FLOAT_EQ(rec->channel(rec->find_channel("surface_rh"))[0], float(want.surface_rh));
    const auto prof = as<Field2D>(s.get("air", "profile", values_only()));
    const sim::ReferenceProfile ref = sim::make_reference(want, prof->height(), 40.0);
    for (int k = 0; k < prof->height(); ++k) {
        EXPECT_NEAR(prof->channel(0)[size_t(k)], ref.theta[size_t(k)], 1e-4 * ref.theta[size_t(k)]);
        EXPECT_NEAR(prof->channel(2)[size_t(k)], ref.pressure[size_t(k)], 1e-5 * ref.pressure[size_t(k)]);
    }
    // The inversion shows: theta rises faster across it than below it.
    const int below = 300 / 40, across = 520 / 40;
    EXPECT_GT(prof->channel(0)[size_t(across)] - prof->channel(0)[size_t(across - 1)],
              2 * (prof->channel(0)[size_t(below)] - prof->channel(0)[size_t(below - 1)]));
}

TEST(SimNodes, EmitterGroundPatchShapeAndSeed) {
    Session s(builtin_nodes());
    s.load_text(kGraph, "sim.yaml", fs::temp_directory_path());
    s.set("patch", "noise_amount", 0.0);
    const auto smooth = as<Field3D>(s.get("patch", "out", values_only()));
    ASSERT_EQ(smooth->channels(), 2);
    // Without noise: exactly heat_rate cos^2(pi r / 2R) (1 - h / depth), zero outside.
    double checked = 0;
    for (int z = 0; z < smooth->nz(); ++z)
        for (int y = 0; y < smooth->ny(); ++y)
            for (int x = 0; x < smooth->nx(); ++x) {
                const Vec3d p = smooth->voxel_center(x, y, z);
                const double r = std::hypot(p[0] - 320, p[1] - 320) / 200;
                const double want = (r < 1 && p[2] <= 120) ? 0.05 * std::pow(std::cos(M_PI * r / 2), 2) * (1 - p[2] / 120) : 0.0;
                ASSERT_NEAR(smooth->at(0, x, y, z), want, 1e-6);
                ASSERT_NEAR(smooth->at(1, x, y, z), want * 1e-4, 1e-10);
                checked += want;
            }
    EXPECT_GT(checked, 0);
    // With noise: within (1 -+ a) of the smooth patch, seeded.
    s.set("patch", "noise_amount", 0.5);
    const auto noisy = as<Field3D>(s.get("patch", "out", values_only()));
    bool differs = false;
    for (size_t i = 0; i < noisy->voxel_count(); ++i) {
        const float a = noisy->channel(0)[i], b = smooth->channel(0)[i];
        ASSERT_GE(a, 0.5f * b - 1e-7f);
        ASSERT_LE(a, 1.5f * b + 1e-7f);
        differs = differs || a != b;
    }
    EXPECT_TRUE(differs);
    s.set("patch", "seed", int64_t(4));
    const auto other = as<Field3D>(s.get("patch", "out", values_only()));
    EXPECT_FALSE(*other == *noisy);
    s.set("patch", "seed", int64_t(3));
    EXPECT_TRUE(*as<Field3D>(s.get("patch", "out", values_only())) == *noisy);
}

// The test graph's run done by hand with the library: same grid, sounding,
// emitter cells and bubble, 4 steps of 10 s.
std::unique_ptr<sim::Simulation> library_run(const Field3D& patch, const sim::SimOptions& o,
                                             sim::BoundarySet boundary = sim::all_closed()) {
    sim::GridSpec spec;
    spec.nx = spec.ny = spec.nz = 16;
    spec.dx = 40;
    spec.boundary = boundary;
    auto sim = std::make_unique<sim::Simulation>(spec, graph_sounding(), o);
    // The emitter grid has the same cell centres in x, y; in z it covers the lowest 4 cells.
    std::vector<float> heat(spec.cells(), 0.f), vap(spec.cells(), 0.f), bubble(spec.cells(), 0.f);
    for (int k = 0; k < 16; ++k)
        for (int j = 0; j < 16; ++j)
            for (int i = 0; i < 16; ++i) {
                const size_t n = (size_t(k) * 16 + j) * 16 + i;
                if (k < 4) {
                    heat[n] = patch.at(0, i, j, k);
                    vap[n] = patch.at(1, i, j, k);
                }
                const double l = std::sqrt(std::pow((i + 0.5) * 40 - 320, 2) + std::pow((j + 0.5) * 40 - 320, 2) +
                                           std::pow((k + 0.5) * 40 - 150, 2)) / 150;
                if (l < 1) bubble[n] = float(2 * std::pow(std::cos(0.5 * M_PI * l), 2));
            }
    sim->set_sources(heat, vap);
    sim->add_theta(bubble);
    for (int step = 0; step < 4; ++step) sim->step(10);
    return sim;
}

void expect_same(const Field3D& node, const Field3D& lib, const char* what) {
    ASSERT_EQ(node.voxel_count(), lib.voxel_count()) << what;
    ASSERT_EQ(node.channels(), lib.channels()) << what;
    for (int c = 0; c < lib.channels(); ++c)
        for (size_t i = 0; i < lib.voxel_count(); ++i) ASSERT_EQ(node.channel(c)[i], lib.channel(c)[i]) << what << " " << c << " " << i;
}

TEST(SimNodes, CloudGrowthMatchesTheLibraryRunByHand) {
    Session s(builtin_nodes());
    s.load_text(kGraph, "sim.yaml", fs::temp_directory_path());
    const auto patch = as<Field3D>(s.get("patch", "out", values_only()));
    const auto density = as<Field3D>(s.get("cloud", "out", values_only()));

    sim::SimOptions o;
    o.projection.tolerance = 1e-7;
    const auto run = library_run(*patch, o);
    const sim::Simulation& sim = *run;
    const Field3D qc = sim.cloud_water();
    ASSERT_EQ(density->channel_name(0), "density");
    ASSERT_EQ(density->voxel_count(), qc.voxel_count());
    double max_qc = 0;
    for (size_t i = 0; i < qc.voxel_count(); ++i) {
        ASSERT_EQ(density->channel(0)[i], qc.channel(0)[i]) << i;
        max_qc = std::max(max_qc, double(qc.channel(0)[i]));
    }
    EXPECT_GT(max_qc, 1e-6) << "the case should form cloud";
    EXPECT_EQ(density->bounds().max[2], 640.0);

    // Report: one row of metrics per step, with the stated quantities (a new
    // session, so the node cooks rather than coming from the memory cache).
    Session fresh(builtin_nodes());
    fresh.load_text(kGraph, "sim.yaml", fs::temp_directory_path());
    CookOptions co = values_only();
    co.outputs = {"final.vdb"};
    const CookResult r = fresh.cook(co);
    const auto& m = r.nodes.at("cloud").metrics;
    EXPECT_EQ(m.at("steps"), 4.0);
    for (const char* k : {"div_l2", "div_max", "pressure_iterations", "water_drift", "theta_l_drift", "seconds_advect",
                          "seconds_project", "seconds_thermo", "substeps"})
        for (int step = 1; step <= 4; ++step) {
            char key[64];
            std::snprintf(key, sizeof key, "step_%04d.%s", step, k);
            ASSERT_TRUE(m.count(key)) << key;
        }
    EXPECT_FALSE(m.count("step_0005.div_l2"));
    EXPECT_LT(m.at("div_max_max"), 1e-4);
    EXPECT_LT(m.at("water_drift_max"), 1e-5);
    EXPECT_GT(m.at("pressure_iterations"), 0.0);
}

// boundary_x / boundary_y: periodic x and y (over a closed floor and lid, and
// with the open top of 'boundary'), the same bit for bit as the library run by
// hand with that BoundarySet; an odd periodic resolution is refused naming the
// parameter.
TEST(SimNodes, PeriodicBoundariesMatchTheLibraryRunByHand) {
    for (bool open_top : {false, true}) {
        Session s(builtin_nodes());
        s.load_text(kGraph, "sim.yaml", fs::temp_directory_path());
        s.set("cloud", "boundary_x", std::string("periodic"));
        s.set("cloud", "boundary_y", std::string("periodic"));
        if (open_top) s.set("cloud", "boundary", std::string("open_top"));
        const auto patch = as<Field3D>(s.get("patch", "out", values_only()));
        const auto density = as<Field3D>(s.get("cloud", "out", values_only()));
        const auto vel = as<Field3D>(s.get("cloud", "velocity", values_only()));
        sim::SimOptions o;
        o.projection.tolerance = 1e-7;
        sim::BoundarySet b = sim::all_closed();
        b[0] = b[1] = b[2] = b[3] = sim::Boundary::Periodic;
        if (open_top) b[5] = sim::Boundary::Open;
        const auto run = library_run(*patch, o, b);
        expect_same(*density, run->cloud_water(), "qc");
        expect_same(*vel, run->velocity_field(), "velocity");
        // Not the closed run: the flow crosses the periodic faces.
        const auto closed = library_run(*patch, o);
        EXPECT_FALSE(*vel == closed->velocity_field());
        double through = 0;
        for (int k = 0; k < 16; ++k)
            for (int j = 0; j < 16; ++j) through = std::max(through, double(std::fabs(run->velocity().u[run->velocity().iu(0, j, k)])));
        EXPECT_GT(through, 0.0);
    }
    Session s(builtin_nodes());
    s.load_text(kGraph, "sim.yaml", fs::temp_directory_path());
    s.set("cloud", "boundary_y", std::string("periodic"));
    s.set("cloud", "resolution", std::vector<double>{16, 15, 16});
    const std::string e = error_of(s, "cloud", "out");
    EXPECT_NE(e.find("boundary_y"), std::string::npos) << e;
    EXPECT_NE(e.find("even"), std::string::npos) << e;
}

// Periodic x: an emitter field reaching over the x- face (bounds x in [-320,
// 320] m) and a bubble centred on it (x = 0) wrap around to the x+ side; the
// node equals the library run with the wrapped sources and the bubble computed
// by hand from the nearest image of its centre.
TEST(SimNodes, PeriodicEmitterAndBubbleWrapAcrossTheSeam) {
    Session s(builtin_nodes());
    s.load_text(kGraph, "sim.yaml", fs::temp_directory_path());
    s.set("cloud", "boundary_x", std::string("periodic"));
    s.set("patch", "bounds_min", std::vector<double>{-320, 0, 0});
    s.set("patch", "bounds_max", std::vector<double>{320, 640, 160});
    s.set("patch", "center", std::vector<double>{0, 320});
    s.set("cloud", "bubble_center", std::vector<double>{0, 320, 150});
    const auto patch = as<Field3D>(s.get("patch", "out", values_only()));
    const auto density = as<Field3D>(s.get("cloud", "out", values_only()));
    const auto temperature = as<Field3D>(s.get("cloud", "temperature", values_only()));

    sim::GridSpec spec;
    spec.nx = spec.ny = spec.nz = 16;
    spec.dx = 40;
    spec.boundary[0] = spec.boundary[1] = sim::Boundary::Periodic;
    sim::SimOptions o;
    o.projection.tolerance = 1e-7;
    sim::Simulation sim(spec, graph_sounding(), o);
    std::vector<float> heat(spec.cells(), 0.f), vap(spec.cells(), 0.f), bubble(spec.cells(), 0.f);
    for (int k = 0; k < 16; ++k)
        for (int j = 0; j < 16; ++j)
            for (int i = 0; i < 16; ++i) {
                const size_t n = (size_t(k) * 16 + j) * 16 + i;
                const int e = (i + 8) % 16; // emitter cell e is at x = -300 + 40 e; grid cell i at 20 + 40 i (mod 640)
                if (k < 4) {
                    heat[n] = patch->at(0, e, j, k);
                    vap[n] = patch->at(1, e, j, k);
                }
                const double x = std::min((i + 0.5) * 40, 640 - (i + 0.5) * 40); // distance to x = 0 across the seam
                const double l = std::sqrt(x * x + std::pow((j + 0.5) * 40 - 320, 2) + std::pow((k + 0.5) * 40 - 150, 2)) / 150;
                if (l < 1) bubble[n] = float(2 * std::pow(std::cos(0.5 * M_PI * l), 2));
            }
    double wrapped = 0;
    for (int i = 8; i < 16; ++i) wrapped += heat[size_t(8) * 16 + i];
    EXPECT_GT(wrapped, 0.0) << "half of the patch lies beyond x- and must reach the x+ cells";
    sim.set_sources(heat, vap);
    sim.add_theta(bubble);
    for (int step = 0; step < 4; ++step) sim.step(10);
    expect_same(*density, sim.cloud_water(), "qc");
    expect_same(*temperature, sim.temperature(), "temperature");
}

// The options the node passes through (rain with no threshold and k1 = 1/s so rain
// forms within 40 s, the cubic scheme, advection-reflection, reversible
// theta_e): the node equals the library run bit for bit, and rain is >= 0.
TEST(SimNodes, CloudGrowthWithRainAndSchemeOptionsMatchesTheLibrary) {
    Session s(builtin_nodes());
    s.load_text(kGraph, "sim.yaml", fs::temp_directory_path());
    s.set("cloud", "rain", true);
    s.set("cloud", "rain_autoconversion_threshold", 0.0);
    s.set("cloud", "rain_autoconversion_rate", 1.0);
    const auto patch = as<Field3D>(s.get("patch", "out", values_only()));
    sim::SimOptions o;
    o.projection.tolerance = 1e-7;
    o.rain = true;
    o.kessler.autoconversion_threshold = 0;
    o.kessler.autoconversion_rate = 1.0;
    {
        const auto run = library_run(*patch, o);
        const auto rain = as<Field3D>(s.get("cloud", "rain", values_only()));
        ASSERT_EQ(rain->channel_name(0), "rain");
        expect_same(*rain, run->rain_water(), "rain");
        expect_same(*as<Field3D>(s.get("cloud", "out", values_only())), run->cloud_water(), "qc");
        expect_same(*as<Field3D>(s.get("cloud", "velocity", values_only())), run->velocity_field(), "velocity");
        double max_qr = 0;
        for (float q : rain->channel(0)) {
            ASSERT_GE(q, 0.f);
            ASSERT_TRUE(std::isfinite(q));
            max_qr = std::max(max_qr, double(q));
        }
        EXPECT_GT(max_qr, 1e-7) << "the case should rain: max qr " << max_qr;
    }
    s.set("cloud", "scheme", std::string("cubic_limited"));
    s.set("cloud", "advection_reflection", true);
    s.set("cloud", "reversible_theta_e", true);
    o.scheme = sim::AdvectionScheme::CubicLimited;
    o.advection_reflection = true;
    o.reversible_theta_e = true;
    const auto run = library_run(*patch, o);
    expect_same(*as<Field3D>(s.get("cloud", "rain", values_only())), run->rain_water(), "rain (all options)");
    expect_same(*as<Field3D>(s.get("cloud", "out", values_only())), run->cloud_water(), "qc (all options)");
    expect_same(*as<Field3D>(s.get("cloud", "temperature", values_only())), run->temperature(), "T (all options)");
    // The memory estimate the node checks and reports counts the options' extra fields.
    {
        Session fresh(builtin_nodes());
        fresh.load_text(kGraph, "sim.yaml", fs::temp_directory_path());
        fresh.set("cloud", "rain", true);
        fresh.set("cloud", "advection_reflection", true);
        CookOptions co = values_only();
        co.outputs = {"final.vdb"};
        const CookResult r = fresh.cook(co);
        const auto& m = r.nodes.at("cloud").metrics;
        EXPECT_EQ(m.at("simulation_bytes"), double(sim::simulation_bytes(run->spec(), o)));
        EXPECT_EQ(m.at("simulation_bytes"), double(16 * 16 * 16 * (sim::kSimBytesPerCell + sim::kSimRainBytesPerCell +
                                                                    sim::kSimReflectionBytesPerCell)));
        EXPECT_TRUE(m.count("max_qr") && m.count("rain_fallout_kg"));
    }
    // Without rain the port still exists and is all zeros.
    s.set("cloud", "rain", false);
    for (float q : as<Field3D>(s.get("cloud", "rain", values_only()))->channel(0)) ASSERT_EQ(q, 0.f);
}

TEST(SimNodes, SequenceWritesReadableVdbFrames) {
    const fs::path dir = temp_dir("seq");
    Session s(builtin_nodes());
    s.load_text(kGraph, "sim.yaml", dir);
    CookOptions co;
    co.out_dir = dir / "out";
    co.jobs = 1;
    const CookResult r = s.cook(co);
    const auto seq = as<Field3D>(s.get("cloud", "sequence", values_only()));
    ASSERT_EQ(seq->channels(), 2 * 4); // 2 frames x (density + vel.x/.y/.z)
    EXPECT_EQ(seq->channel_name(0), "0001:density");
    EXPECT_EQ(seq->channel_name(7), "0002:vel.z");
    // The last frame is the final state.
    const auto density = as<Field3D>(s.get("cloud", "out", values_only()));
    for (size_t i = 0; i < density->voxel_count(); ++i) ASSERT_EQ(seq->channel(4)[i], density->channel(0)[i]);
    for (int f = 1; f <= 2; ++f) {
        const fs::path file = dir / "out" / "seq" / ("cloud.000" + std::to_string(f) + ".vdb");
        ASSERT_TRUE(fs::exists(file)) << file;
        auto grids = io::list_vdb_grids(file);
        std::sort(grids.begin(), grids.end());
        EXPECT_EQ(grids, (std::vector<std::string>{"density", "vel"}));
        const Field3D back = io::read_vdb(file, {"density", "vel"});
        ASSERT_EQ(back.resolution(), seq->resolution());
        EXPECT_EQ(back.bounds(), seq->bounds());
        ASSERT_EQ(back.channels(), 4);
        EXPECT_EQ(back.channel_name(1), "vel.x");
        const int base = (f - 1) * 4;
        for (int c = 0; c < 4; ++c)
            for (size_t i = 0; i < back.voxel_count(); ++i) ASSERT_EQ(back.channel(c)[i], seq->channel(base + c)[i]) << f << " " << c;
    }
    EXPECT_FALSE(fs::exists(dir / "out" / "seq" / "cloud.0003.vdb"));
    bool listed = false;
    for (const auto& o : r.outputs)
        if (o.format == "vdb-sequence") {
            listed = true;
            EXPECT_EQ(o.written.size(), 2u);
            EXPECT_EQ(o.metrics.at("frames"), 2.0);
        }
    EXPECT_TRUE(listed);
    // Same bytes again (deterministic archive UUIDs).
    const auto bytes = [](const fs::path& p) {
        std::ifstream in(p, std::ios::binary);
        return std::string(std::istreambuf_iterator<char>(in), {});
    };
    const std::string first = bytes(dir / "out" / "seq" / "cloud.0002.vdb");
    io::write_value(seq, dir / "again", "vdb-sequence", {});
    EXPECT_EQ(bytes(dir / "again.0002.vdb"), first);
    fs::remove_all(dir);
}

TEST(SimNodes, SequenceFormatRefusesOtherFields) {
    const fs::path dir = temp_dir("bad");
    auto plain = std::make_shared<const Field3D>(Vec3i{{4, 4, 4}}, 1, Box3d{{{0, 0, 0}}, {{1, 1, 1}}}, std::vector<std::string>{"density"});
    try {
        io::write_value(Field3DPtr(plain), dir / "x", "vdb-sequence", {});
        FAIL() << "expected an error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("FRAME:GRID"), std::string::npos) << e.what();
    }
    EXPECT_THROW(io::write_value(Field3DPtr(plain), dir / "x.vdb", "vdb-sequence", {}), Error);
    fs::remove_all(dir);
}

TEST(SimNodes, NonFiniteEmitterNamesTheNode) {
    Session s(builtin_nodes());
    s.load_text(R"(atlas: 1
nodes:
  zero:
    type: field/constant
    params: {resolution: [8, 8, 8], bounds_max: [320, 320, 320], value: 0}
  bad:
    type: math/binary
    inputs: {a: zero}
    params: {op: pow, b: -1}
  source:
    type: sim/emitter
    inputs: {mask: bad}
    params: {mode: mask}
  growth:
    type: sim/cloud_growth
    inputs: {emitter: zero}
    params: {resolution: [8, 8, 8], dx: 40, duration: 10}
outputs:
  - {node: growth, port: out, file: g.vdb}
)",
                "nan.yaml", fs::temp_directory_path());
    // 0^-1 is Inf: the emitter refuses its mask, naming itself.
    const std::string e1 = error_of(s, "source", "out");
    EXPECT_NE(e1.find("node 'source'"), std::string::npos) << e1;
    EXPECT_NE(e1.find("NaN/Inf"), std::string::npos) << e1;
}

TEST(SimNodes, NonFiniteEmitterInputToCloudGrowthNamesTheNode) {
    Session s(builtin_nodes());
    s.load_text(R"(atlas: 1
nodes:
  zero:
    type: field/constant
    params: {resolution: [8, 8, 8], bounds_max: [320, 320, 320], value: 0}
  bad:
    type: math/binary
    inputs: {a: zero}
    params: {op: pow, b: -1}
  growth:
    type: sim/cloud_growth
    inputs: {emitter: bad}
    params: {resolution: [8, 8, 8], dx: 40, duration: 10}
outputs:
  - {node: growth, port: out, file: g.vdb}
)",
                "nan2.yaml", fs::temp_directory_path());
    const std::string e = error_of(s, "growth", "out");
    EXPECT_NE(e.find("node 'growth'"), std::string::npos) << e;
    EXPECT_NE(e.find("NaN/Inf"), std::string::npos) << e;
}

TEST(SimNodes, MemoryIsCheckedBeforeAllocatingAndNamesTheNode) {
    Session s(builtin_nodes());
    s.load_text(kGraph, "sim.yaml", fs::temp_directory_path());
    s.set("cloud", "resolution", std::vector<double>{1024, 1024, 1024}); // 216 GiB of state
    try {
        s.get("cloud", "out", values_only());
        FAIL() << "expected a memory error";
    } catch (const MemoryBudgetError& e) {
        EXPECT_NE(std::string(e.what()).find("node 'cloud'"), std::string::npos) << e.what();
    }
}

TEST(SimNodes, BadSettingsAreErrorsNamingTheNode) {
    Session s(builtin_nodes());
    s.load_text(kGraph, "sim.yaml", fs::temp_directory_path());
    s.set("cloud", "sequence_every", int64_t(0));
    s.set("cloud", "duration", 1000.0);
    s.set("cloud", "frame_dt", 1000.0);
    s.set("cloud", "max_substeps", int64_t(2)); // 1000 s at CFL 1 needs many more substeps
    const std::string e1 = error_of(s, "cloud", "out");
    EXPECT_NE(e1.find("node 'cloud'"), std::string::npos) << e1;
    EXPECT_NE(e1.find("max_substeps"), std::string::npos) << e1;
    s.set("cloud", "max_substeps", int64_t(64));
    s.set("cloud", "sequence_grids", std::string("density, smoke"));
    const std::string e2 = error_of(s, "cloud", "out");
    EXPECT_NE(e2.find("smoke"), std::string::npos) << e2;
    s.set("cloud", "sequence_grids", std::string("density"));
    s.set("cloud", "sequence_every", int64_t(5));
    const std::string e3 = error_of(s, "cloud", "out");
    EXPECT_NE(e3.find("sequence_every"), std::string::npos) << e3;
    s.set("cloud", "sequence_every", int64_t(0));
    s.set("cloud", "resolution", std::vector<double>{1, 1, 16});
    const std::string e4 = error_of(s, "cloud", "out");
    EXPECT_NE(e4.find("node 'cloud'"), std::string::npos) << e4;
}

TEST(SimNodes, ProgressMovesAndCancelStopsTheRun) {
    Session s(builtin_nodes());
    s.load_text(kGraph, "sim.yaml", fs::temp_directory_path());
    s.set("cloud", "duration", 100.0); // 10 steps
    std::mutex mu;
    std::vector<double> seen;
    std::atomic<bool> cancel{false};
    CookOptions co = values_only();
    co.outputs = {"final.vdb"};
    co.progress.on_progress = [&](const ProgressEvent& e) {
        std::lock_guard<std::mutex> l(mu);
        if (e.task.find("'cloud'") != std::string::npos) {
            seen.push_back(e.fraction);
            if (seen.size() == 3) cancel = true; // stop in the middle of the run
        }
    };
    co.progress.is_cancelled = [&] { return cancel.load(); };
    EXPECT_THROW(s.cook(co), CancelledError);
    ASSERT_GE(seen.size(), 3u);
    // The next step's progress call polled the cancel and threw: besides the
    // evaluator's start and end events only two steps reported (a whole run sends 11).
    EXPECT_EQ(seen.size(), 4u);
    for (size_t i = 1; i < seen.size(); ++i) EXPECT_GE(seen[i], seen[i - 1]);

    // Uncancelled, the fraction climbs to 1 (the CLI bar moves).
    cancel = false;
    seen.clear();
    co.progress.on_progress = [&](const ProgressEvent& e) {
        std::lock_guard<std::mutex> l(mu);
        if (e.task.find("'cloud'") != std::string::npos) seen.push_back(e.fraction);
    };
    s.cook(co);
    ASSERT_GE(seen.size(), 11u);
    EXPECT_EQ(seen.back(), 1.0);
    EXPECT_GT(seen.back(), seen.front());
    for (size_t i = 1; i < seen.size(); ++i) EXPECT_GE(seen[i], seen[i - 1]);
}

TEST(SimNodes, SameBytesForAnyThreadCount) {
    std::vector<Field3DPtr> outs;
    for (int jobs : {1, 2}) {
        Session s(builtin_nodes());
        s.load_text(kGraph, "sim.yaml", fs::temp_directory_path());
        CookOptions co = values_only();
        co.jobs = jobs;
        outs.push_back(as<Field3D>(s.get("cloud", "sequence", co)));
    }
    EXPECT_TRUE(*outs[0] == *outs[1]);
}

// The production graph cooks end to end on a small grid (CI only validates it at 128^3).
TEST(SimNodes, CumulusGraphCooksOnASmallGrid) {
    const fs::path dir = temp_dir("cumulus");
    Session s(builtin_nodes());
    s.load(fs::path(ATLAS_SOURCE_DIR) / "graphs" / "cumulus_growth.yaml");
    s.set("cloud", "resolution", std::vector<double>{16, 16, 16});
    s.set("cloud", "dx", 250.0);
    s.set("cloud", "duration", 160.0); // 8 steps of 20 s: one sequence frame
    CookOptions co;
    co.out_dir = dir;
    co.jobs = 2;
    const CookResult r = s.cook(co);
    EXPECT_TRUE(fs::exists(dir / "cumulus" / "cloud.0001.vdb"));
    EXPECT_FALSE(fs::exists(dir / "cumulus" / "cloud.0002.vdb"));
    EXPECT_TRUE(fs::exists(dir / "cumulus_final.vdb"));
    EXPECT_TRUE(fs::exists(dir / "cumulus_final.exr"));
    const Field3D back = io::read_vdb(dir / "cumulus_final.vdb");
    EXPECT_EQ(back.resolution(), (Vec3i{{16, 16, 16}}));
    EXPECT_EQ(back.bounds().max[2], 4000.0);
    const auto& m = r.nodes.at("cloud").metrics;
    EXPECT_EQ(m.at("steps"), 8.0);
    EXPECT_GT(m.at("max_w"), 0.0); // the heated patch and bubble set the air rising
    fs::remove_all(dir);
}

// Published-case set-up from a graph: a 2D (one-cell-thick) slab, an
// ellipsoidal cos^2 bubble given as a temperature perturbation T' (converted
// to theta' = T' / Pi0), an initial_theta input (theta', an aligned sub-box),
// an initial_velocity input, explicit nu and kappa; against the same set-up
// written out by hand with the library.
TEST(SimNodes, InitialStateInputsAndEllipsoidalTemperatureBubbleMatchTheLibrary) {
    const char* graph = R"(atlas: 1
nodes:
  air:
    type: sim/sounding
    params: {theta_lapse: 0.002, inversion_height: 500, inversion_jump: 3, surface_rh: 1, rh_lapse: 0, rh_above: 0.5}
  warm:
    type: field/constant
    params: {resolution: [8, 1, 4], bounds_min: [0, 0, 0], bounds_max: [800, 100, 400], value: 0.5}
  wind:
    type: field/constant
    params: {resolution: [32, 1, 16], bounds_min: [0, 0, 0], bounds_max: [3200, 100, 1600], channels: 3, value: 2}
  cloud:
    type: sim/cloud_growth
    inputs: {sounding: air.out, initial_theta: warm, initial_velocity: wind}
    params: {resolution: [32, 1, 16], dx: 100, duration: 20, frame_dt: 10, moist: false, viscosity: 20, diffusivity: 20,
             bubble_theta: -5, bubble_is_temperature: true, bubble_center: [1600, 50, 800], bubble_radii: [800, 1, 400]}
outputs:
  - {node: cloud, port: temperature, file: t.vdb}
)";
    Session s(builtin_nodes());
    s.load_text(graph, "initial.yaml", fs::temp_directory_path());
    const auto temp = as<Field3D>(s.get("cloud", "temperature", values_only()));
    const auto vel = as<Field3D>(s.get("cloud", "velocity", values_only()));

    sim::GridSpec spec;
    spec.nx = 32, spec.ny = 1, spec.nz = 16, spec.dx = 100;
    sim::SimOptions o;
    o.moist = false;
    o.viscosity = o.diffusivity = 20;
    sim::Simulation sim(spec, graph_sounding(), o);
    std::vector<float> bubble(spec.cells(), 0.f), warm(spec.cells(), 0.f);
    for (int k = 0; k < 16; ++k)
        for (int i = 0; i < 32; ++i) {
            const double l = std::hypot(((i + 0.5) * 100 - 1600) / 800, ((k + 0.5) * 100 - 800) / 400);
            const float tp = l < 1 ? float(-5 * std::pow(std::cos(0.5 * M_PI * l), 2)) : 0.f; // T'
            bubble[size_t(k) * 32 + i] = float(tp / sim.reference().exner[size_t(k)]);
            if (i < 8 && k < 4) warm[size_t(k) * 32 + i] = 0.5f;
        }
    sim.add_theta(bubble);
    sim.add_theta(warm);
    sim::MacVelocity& v = sim.velocity();
    std::fill(v.u.begin(), v.u.end(), 2.f); // cell-centre means of a constant 2 m/s
    std::fill(v.w.begin(), v.w.end(), 2.f);
    v.enforce_walls(); // closed box: 0 on the walls; v is 0 in the single-cell y direction
    sim.step(10);
    sim.step(10);
    expect_same(*temp, sim.temperature(), "temperature");
    expect_same(*vel, sim.velocity_field(), "velocity");
    // The cold bubble is there: T' reached about -5 K at its centre initially.
    double min_tp = 0;
    // theta_perturbation() returns a field by value: keep it alive while its channel is read.
    const auto tp_field = sim.theta_perturbation();
    for (float t : tp_field.channel(0)) min_tp = std::min(min_tp, double(t));
    EXPECT_LT(min_tp, -4.0);
}

TEST(SimNodes, NegativeInitialVapourIsRefusedAndCoolingEmittersAreAllowed) {
    Session s(builtin_nodes());
    s.load_text(R"(atlas: 1
nodes:
  dry:
    type: field/constant
    params: {resolution: [8, 1, 8], bounds_min: [0, 0, 0], bounds_max: [800, 100, 800], value: -1}
  cool:
    type: sim/emitter
    params: {resolution: [8, 1, 8], bounds_max: [800, 100, 800], center: [400, 50], radius: 300, depth: 300,
             heat_rate: -0.05, vapour_rate: 0, noise_amount: 0}
  cloud:
    type: sim/cloud_growth
    inputs: {initial_vapour: dry}
    params: {resolution: [8, 1, 8], dx: 100, duration: 10, frame_dt: 10}
outputs:
  - {node: cloud, port: out, file: c.vdb}
)",
                "vapour.yaml", fs::temp_directory_path());
    const std::string e = error_of(s, "cloud", "out");
    EXPECT_NE(e.find("node 'cloud'"), std::string::npos) << e;
    EXPECT_NE(e.find("initial_vapour"), std::string::npos) << e;
    const auto cool = as<Field3D>(s.get("cool", "out", values_only()));
    float lo = 0;
    for (float h : cool->channel(0)) lo = std::min(lo, h);
    EXPECT_LT(lo, -0.01f);
}

// boundary: open_sides = free-slip floor and lid, open x (and y) faces: the same
// run as the library with that BoundarySet, bit for bit.
TEST(SimNodes, OpenSidesBoundaryMatchesTheLibrary) {
    Session s(builtin_nodes());
    s.load_text(R"(atlas: 1
nodes:
  cloud:
    type: sim/cloud_growth
    params: {resolution: [16, 1, 8], dx: 100, duration: 20, frame_dt: 10, moist: false, boundary: open_sides,
             bubble_theta: 2, bubble_center: [300, 50, 300], bubble_radius: 250}
outputs:
  - {node: cloud, port: velocity, file: v.vdb}
)",
                "sides.yaml", fs::temp_directory_path());
    const auto vel = as<Field3D>(s.get("cloud", "velocity", values_only()));
    sim::GridSpec spec;
    spec.nx = 16, spec.ny = 1, spec.nz = 8, spec.dx = 100;
    spec.boundary = sim::all_open();
    spec.boundary[4] = spec.boundary[5] = sim::Boundary::Closed;
    sim::Sounding snd; // the node's defaults for an unconnected sounding
    snd.theta_lapse = 0.003;
    snd.inversion_height = 2500;
    snd.inversion_jump = 4;
    snd.theta_lapse_above = 0.004;
    snd.surface_rh = 0.85;
    snd.rh_lapse = -1e-4;
    snd.rh_above = 0.3;
    sim::SimOptions o;
    o.moist = false;
    sim::Simulation sim(spec, snd, o);
    std::vector<float> d(spec.cells(), 0.f);
    for (int k = 0; k < 8; ++k)
        for (int i = 0; i < 16; ++i) {
            const double l = std::hypot((i + 0.5) * 100 - 300, (k + 0.5) * 100 - 300) / 250;
            if (l < 1) d[size_t(k) * 16 + i] = float(2 * std::pow(std::cos(0.5 * M_PI * l), 2));
        }
    sim.add_theta(d);
    sim.step(10);
    sim.step(10);
    expect_same(*vel, sim.velocity_field(), "velocity");
    double edge_u = 0; // the open x faces let the flow through
    for (int k = 0; k < 8; ++k) edge_u = std::max(edge_u, double(std::fabs(sim.velocity().u[sim.velocity().iu(0, 0, k)])));
    EXPECT_GT(edge_u, 0.0);
}

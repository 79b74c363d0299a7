// The volume nodes through the graph engine: they must give the library's results.
#include "atlas/core/error.h"
#include "atlas/graph/evaluator.h"
#include "atlas/graph/node.h"
#include "atlas/volume/edit.h"
#include "atlas/volume/mesh_io.h"
#include "atlas/volume/mesh_primitives.h"
#include "atlas/volume/mesh_voxelize.h"
#include "atlas/volume/nvdf.h"
#include "atlas/volume/sdf.h"
#include "atlas/volume/splat.h"

#include <gtest/gtest.h>

#include <filesystem>

using namespace atlas;

namespace {

const char* kGraph = R"(atlas: 1
nodes:
  world:
    type: volume/world
    params: {resolution: [32, 32, 8], bounds_max: [256, 256, 64]}
  balls:
    type: volume/metaballs
    params: {resolution: [32, 32, 8], bounds_max: [256, 256, 64], kernel: sphere, spheres: "100 120 32 40; 160 120 30 30"}
  comp:
    type: volume/composite
    inputs: {world: world, cloud: balls}
    params: {op: max}
  cut:
    type: volume/cutout
    inputs: {in: comp}
    params: {shape: sphere, a: [130, 120, 32], radius: 20}
  sdf:
    type: volume/sdf
    inputs: {in: cut}
  swept:
    type: volume/sdf
    inputs: {in: cut}
    params: {method: fast_sweeping, check_error: true}
  nvdf:
    type: volume/nvdf
    inputs: {sdf: sdf}
    params: {depth: 16, detail_type: 0.25}
  ring:
    type: volume/mesh_primitive
    params: {shape: torus, center: [128, 128, 32], radius: 60, minor_radius: 20, segments: 24}
  fill:
    type: volume/interior_fill
    inputs: {mesh: ring}
    params: {target_samples: 50}
  mesh_sdf:
    type: volume/mesh_to_sdf
    inputs: {mesh: ring}
    params: {resolution: [32, 32, 8], bounds_max: [256, 256, 64]}
outputs:
  - {node: nvdf, port: vdb_set, file: set.vdb}
  - {node: swept, file: swept.vdb}
)";

template <typename T>
std::shared_ptr<const T> as(const Value& v) {
    return std::get<std::shared_ptr<const T>>(v);
}

} // namespace

TEST(VolumeNodes, GraphMatchesLibrary) {
    Session s(builtin_nodes());
    s.load_text(kGraph, "volume_nodes.yaml", std::filesystem::temp_directory_path());
    CookOptions co;
    co.write_outputs = false;
    const Box3d box{{{0, 0, 0}}, {{256, 256, 64}}};
    Points p;
    p.positions = {{{100, 120, 32}}, {{160, 120, 30}}};
    p.attributes["radius"] = {40, 30};
    volume::SplatOptions so;
    so.kernel = volume::SplatKernel::Sphere;
    const Field3D balls = volume::splat_points(p, {{32, 32, 8}}, box, so);
    volume::Shape hole;
    hole.a = {{130, 120, 32}};
    hole.radius = 20;
    const Field3D cut = volume::cutout_density(volume::composite(Field3D({{32, 32, 8}}, 1, box, {"density"}), balls, volume::CompositeOp::Max), hole);
    EXPECT_TRUE(*as<Field3D>(s.get("cut", "out", co)) == cut);
    const Field3D sdf = volume::sdf_from_density_edt(cut, {});
    EXPECT_TRUE(*as<Field3D>(s.get("sdf", "out", co)) == sdf);
    auto set = as<Field3D>(s.get("nvdf", "vdb_set", co));
    ASSERT_EQ(set->channels(), 4);
    volume::DimensionalProfileOptions dpo;
    dpo.depth = 16;
    const Field3D dp = volume::dimensional_profile(sdf, dpo);
    for (size_t i = 0; i < sdf.voxel_count(); ++i) {
        ASSERT_EQ(set->channel(0)[i], dp.channel(0)[i]);
        ASSERT_EQ(set->channel(1)[i], 0.25f);
        ASSERT_EQ(set->channel(2)[i], 1.0f);
        ASSERT_EQ(set->channel(3)[i], sdf.channel(0)[i]);
    }
    auto fd = as<Field3D>(s.get("nvdf", "field_data", co));
    EXPECT_TRUE(*fd == volume::encode_field_data(sdf));
    const CookResult r = s.cook([&] { CookOptions c = co; c.outputs = {"swept.vdb"}; return c; }());
    const auto& m = r.nodes.at("swept").metrics;
    ASSERT_TRUE(m.count("max_error_voxels"));
    EXPECT_LT(m.at("max_error_voxels"), 2.0);
    EXPECT_EQ(m.at("sign_errors"), 0.0);
    auto pts = as<Points>(s.get("fill", "out", co));
    EXPECT_GT(pts->positions.size(), 10u);
    EXPECT_EQ(pts->attributes.at("radius").size(), pts->positions.size());
    auto msdf = as<Field3D>(s.get("mesh_sdf", "sdf", co));
    EXPECT_TRUE(*msdf == volume::mesh_to_sdf(volume::make_torus_mesh({{128, 128, 32}}, 60, 20, 24, 12), {{32, 32, 8}}, box));
}

TEST(VolumeNodes, BadParametersNameTheProblem) {
    Session s(builtin_nodes());
    s.load_text(R"(atlas: 1
nodes:
  balls:
    type: volume/metaballs
    params: {resolution: [8, 8, 8], spheres: "1 2 three 4"}
outputs:
  - {node: balls, file: b.vdb}
)",
                "bad.yaml", std::filesystem::temp_directory_path());
    CookOptions co;
    co.write_outputs = false;
    try {
        s.get("balls", "out", co);
        FAIL() << "expected an error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("spheres"), std::string::npos) << e.what();
    }
}

TEST(VolumeNodes, ReadMeshNodeRepairs) {
    const auto dir = std::filesystem::temp_directory_path() / ("atlas_vnodes_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    Mesh m = volume::make_box_mesh({{4, 4, 4}}, {{2, 2, 2}});
    for (auto& t : m.triangles) std::swap(t[1], t[2]); // inside out
    volume::write_mesh(dir / "box.off", m);
    Session s(builtin_nodes());
    s.load_text("atlas: 1\nnodes:\n  m:\n    type: volume/read_mesh\n    params: {file: box.off}\n  f:\n    type: volume/mesh_to_sdf\n    inputs: {mesh: m}\n    params: {resolution: [8, 8, 8], bounds_max: [8, 8, 8]}\noutputs:\n  - {node: f, port: sdf, file: f.vdb}\n", "g.yaml", dir);
    CookOptions co;
    co.write_outputs = false;
    auto mesh = as<Mesh>(s.get("m", "out", co));
    EXPECT_EQ(mesh->triangles.size(), 12u);
    EXPECT_NEAR(volume::winding_number(*mesh, {{4, 4, 4}}), 1.0, 1e-9);
    std::filesystem::remove_all(dir);
}

TEST(VolumeNodes, CloudscapeGraphValidates) {
    Session s(builtin_nodes());
    EXPECT_NO_THROW(s.load(std::filesystem::path(ATLAS_SOURCE_DIR) / "graphs" / "cloudscape.yaml"));
}

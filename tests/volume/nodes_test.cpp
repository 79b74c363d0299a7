// The volume nodes through the graph engine: they must give the library's results.
#include "atlas/core/error.h"
#include "atlas/graph/evaluator.h"
#include "atlas/graph/node.h"
#include "atlas/io/geometry_files.h"
#include "atlas/volume/edit.h"
#include "atlas/volume/mesh_repair.h"
#include "atlas/volume/mesh_primitives.h"
#include "atlas/volume/mesh_voxelize.h"
#include "atlas/volume/nvdf.h"
#include "atlas/volume/sdf.h"
#include "atlas/volume/splat.h"

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <unistd.h>

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
    io::write_mesh(dir / "box.off", m);
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

// ---------------------------------------------------------------- the Nubis pack through the graph

namespace {

namespace fs = std::filesystem;

// A synthetic pack slice in the pack's shape, encoded here (not by Atlas): 32-bit
// RLE, bottom-left origin, packets running across rows as a whole-image stream.
// `px` is RGBA, row 0 at the bottom.
void write_pack_slice(const fs::path& p, int w, int h, const std::vector<uint8_t>& px) {
    std::vector<uint8_t> b(18, 0);
    b[2] = 10;
    b[12] = uint8_t(w & 255), b[13] = uint8_t(w >> 8), b[14] = uint8_t(h & 255), b[15] = uint8_t(h >> 8);
    b[16] = 32, b[17] = 8;
    const size_t n = size_t(w) * size_t(h);
    auto bgra = [&](size_t i) { return std::array<uint8_t, 4>{px[i * 4 + 2], px[i * 4 + 1], px[i * 4 + 0], px[i * 4 + 3]}; };
    for (size_t i = 0; i < n;) {
        size_t r = 1;
        while (i + r < n && r < 128 && bgra(i + r) == bgra(i)) ++r;
        if (r >= 2) {
            b.push_back(uint8_t(0x80 | (r - 1)));
            for (uint8_t v : bgra(i)) b.push_back(v);
            i += r;
            continue;
        }
        size_t j = i + 1;
        while (j < n && j - i < 128 && !(j + 1 < n && bgra(j + 1) == bgra(j))) ++j;
        b.push_back(uint8_t(j - i - 1));
        for (size_t k = i; k < j; ++k)
            for (uint8_t v : bgra(k)) b.push_back(v);
        i = j;
    }
    std::ofstream(p, std::ios::binary).write(reinterpret_cast<const char*>(b.data()), std::streamsize(b.size()));
}

// A slice read by OpenImageIO, RGBA, row 0 at the bottom, alpha unassociated.
std::vector<uint8_t> oiio_rgba(const fs::path& p) {
    OIIO::ImageSpec config;
    config.attribute("oiio:UnassociatedAlpha", 1);
    auto in = OIIO::ImageInput::open(p.string(), &config);
    if (!in) throw Error(p.string() + ": OpenImageIO cannot open it");
    const int w = in->spec().width, h = in->spec().height;
    std::vector<uint8_t> top(size_t(w) * size_t(h) * 4), out(top.size());
    if (in->spec().nchannels != 4 || !in->read_image(0, 0, 0, 4, OIIO::TypeDesc::UINT8, top.data())) throw Error(p.string() + ": not RGBA");
    for (int y = 0; y < h; ++y) std::copy_n(top.data() + size_t(h - 1 - y) * size_t(w) * 4, size_t(w) * 4, out.data() + size_t(y) * size_t(w) * 4);
    return out;
}

struct PackDir {
    fs::path path = fs::temp_directory_path() / ("atlas_vnodes_pack_" + std::to_string(::getpid()));
    PackDir() {
        fs::remove_all(path);
        fs::create_directories(path / "pack");
    }
    ~PackDir() { fs::remove_all(path); }
};

constexpr int kW = 48, kH = 40, kD = 6;
constexpr double kDepth = 64;

// Synthetic modeling_data(k).tga and field_data(k).tga: a sphere's SDF (8 m
// voxels), dimensional profile in R, detail type and density scale in G and B
// with flat regions, A = 0; field data R = encoded SDF, A = 255.
void make_pack(const fs::path& dir, std::vector<std::vector<uint8_t>>& modeling, std::vector<std::vector<uint8_t>>& field) {
    for (int z = 0; z < kD; ++z) {
        std::vector<uint8_t> m(size_t(kW) * kH * 4), f(size_t(kW) * kH * 4);
        for (int y = 0; y < kH; ++y)
            for (int x = 0; x < kW; ++x) {
                const double px = (x + 0.5) * 8 - 200, py = (y + 0.5) * 8 - 160, pz = (z + 0.5) * 8 - 24;
                const double sdf = std::sqrt(px * px + py * py + pz * pz) - 120;
                const size_t i = (size_t(y) * kW + size_t(x)) * 4;
                m[i + 0] = uint8_t(std::lround(255 * std::clamp(-sdf / kDepth, 0.0, 1.0)));
                m[i + 1] = uint8_t(x < 20 ? 64 : 64 + 8 * (y / 5));
                m[i + 2] = uint8_t(y < 16 ? 255 : 200 + z);
                m[i + 3] = 0;
                f[i + 0] = uint8_t(std::lround(255 * std::clamp((sdf + 256) / 4352, 0.0, 1.0)));
                f[i + 1] = f[i + 2] = 0;
                f[i + 3] = 255;
            }
        write_pack_slice(dir / ("modeling_data(" + std::to_string(z) + ").tga"), kW, kH, m);
        write_pack_slice(dir / ("field_data(" + std::to_string(z) + ").tga"), kW, kH, f);
        modeling.push_back(std::move(m));
        field.push_back(std::move(f));
    }
}

uint64_t stack_bytes(const fs::path& dir, const std::string& stem) {
    uint64_t n = 0;
    for (int z = 0; z < kD; ++z) n += fs::file_size(dir / (stem + "(" + std::to_string(z) + ").tga"));
    return n;
}

} // namespace

// Import a pack in its own naming and encoding, write it back with the same
// options: the same pixels (read by OpenImageIO) and a comparable size. The
// modeling NVDF rebuilt by volume/nvdf from the pack's channels keeps its
// detail type and density scale bytes.
TEST(VolumeNodes, PackImportAndWriteBack) {
    PackDir dir;
    std::vector<std::vector<uint8_t>> modeling, field;
    make_pack(dir.path / "pack", modeling, field);
    const std::string graph = R"(atlas: 1
nodes:
  modeling:
    type: import/tga_slices
    params: {file: "pack/modeling_data(0).tga", bounds_max: [384, 320, 48]}
  field:
    type: import/tga_slices
    params: {file: pack/field_data, bounds_max: [384, 320, 48], channels: 1}
  sdf:
    type: volume/field_data
    inputs: {in: field}
    params: {mode: decode}
  nvdf:
    type: volume/nvdf
    inputs: {sdf: sdf, detail_type: modeling, density_scale: modeling}
    params: {depth: 64, detail_type_channel: g, density_scale_channel: "2"}
outputs:
  - {node: modeling, file: out/modeling_data, format: tga-slices, options: {naming: nubis, compression: rle}}
  - {node: field, file: out/field_data, format: tga-slices, options: {naming: nubis, compression: rle, alpha: 255}}
  - {node: nvdf, port: modeling, file: rebuilt/modeling_data, format: tga-slices, options: {naming: nubis, alpha: 0}}
)";
    Session s(builtin_nodes());
    s.load_text(graph, "pack.yaml", dir.path);
    CookOptions co;
    co.out_dir = dir.path;
    s.cook(co);
    for (int z = 0; z < kD; ++z) {
        const std::string k = "(" + std::to_string(z) + ").tga";
        ASSERT_EQ(oiio_rgba(dir.path / "out" / ("modeling_data" + k)), modeling[size_t(z)]) << z;
        const auto f = oiio_rgba(dir.path / "out" / ("field_data" + k));
        for (size_t i = 0; i < f.size(); ++i) ASSERT_EQ(f[i], field[size_t(z)][i]) << z << " byte " << i; // R read; G, B 0; A 255
        const auto r = oiio_rgba(dir.path / "rebuilt" / ("modeling_data" + k));
        for (size_t i = 0; i < r.size(); i += 4) {
            ASSERT_EQ(r[i + 1], modeling[size_t(z)][i + 1]) << "detail type, slice " << z;
            ASSERT_EQ(r[i + 2], modeling[size_t(z)][i + 2]) << "density scale, slice " << z;
            ASSERT_EQ(r[i + 3], 0);
            // R: the profile of the pack's own (8-bit) SDF.
            const double sdf = field[size_t(z)][i] / 255.0 * 4352 - 256;
            ASSERT_NEAR(r[i], 255 * std::clamp(-sdf / kDepth, 0.0, 1.0), 0.5 + 1e-3) << "slice " << z;
        }
    }
    const double m_in = double(stack_bytes(dir.path / "pack", "modeling_data")), m_out = double(stack_bytes(dir.path / "out", "modeling_data"));
    const double f_in = double(stack_bytes(dir.path / "pack", "field_data")), f_out = double(stack_bytes(dir.path / "out", "field_data"));
    const double raw = double(kD) * (18 + kW * kH * 4);
    EXPECT_LT(m_out, 0.6 * raw) << "RLE must be smaller than the raw stack";
    EXPECT_GT(m_out / m_in, 0.85) << m_out << " vs " << m_in;
    EXPECT_LT(m_out / m_in, 1.2) << m_out << " vs " << m_in;
    EXPECT_GT(f_out / f_in, 0.85) << f_out << " vs " << f_in;
    EXPECT_LT(f_out / f_in, 1.2) << f_out << " vs " << f_in;
}

TEST(VolumeNodes, NvdfChannelSelectorErrorsNameTheParameter) {
    PackDir dir;
    std::vector<std::vector<uint8_t>> modeling, field;
    make_pack(dir.path / "pack", modeling, field);
    auto run = [&](const std::string& params) {
        Session s(builtin_nodes());
        s.load_text(R"(atlas: 1
nodes:
  modeling:
    type: import/tga_slices
    params: {file: "pack/modeling_data(0).tga", bounds_max: [384, 320, 48]}
  sdf:
    type: volume/field_data
    inputs: {in: modeling}
    params: {mode: decode}
  nvdf:
    type: volume/nvdf
    inputs: {sdf: sdf, detail_type: modeling}
    params: )" + params + R"(
outputs:
  - {node: nvdf, port: modeling, file: m.vdb}
)",
                    "sel.yaml", dir.path);
        CookOptions co;
        co.write_outputs = false;
        s.get("nvdf", "modeling", co);
    };
    auto expect_error = [&](const std::string& params, std::initializer_list<const char*> parts) {
        try {
            run(params);
            ADD_FAILURE() << "expected an error for " << params;
        } catch (const Error& e) {
            const std::string w = e.what();
            for (const char* p : parts) EXPECT_NE(w.find(p), std::string::npos) << "'" << p << "' not in: " << w;
        }
    };
    expect_error("{}", {"nvdf", "detail_type_channel", "4 channels", "'g'"});
    expect_error("{detail_type_channel: q}", {"nvdf", "detail_type_channel", "no channel 'q'", "0..3"});
    expect_error("{detail_type_channel: \"7\"}", {"nvdf", "detail_type_channel", "'7'"});
    expect_error("{detail_type_channel: g, density_scale_channel: b}", {"nvdf", "density_scale_channel", "not connected"});
    EXPECT_NO_THROW(run("{detail_type_channel: \"1\"}"));
}

// The SDF of a dimensional profile: its default iso (2/255) puts the surface
// where the profile leaves 0, i.e. on the cloud's surface; the density default
// (0.5) would put it depth/2 inside.
TEST(VolumeNodes, SdfOfDimensionalProfileDefaultsToItsIso) {
    Session s(builtin_nodes());
    s.load_text(R"(atlas: 1
nodes:
  balls:
    type: volume/metaballs
    params: {resolution: [40, 40, 24], bounds_max: [320, 320, 192], kernel: sphere, spheres: "160 160 96 80"}
  sdf:
    type: volume/sdf
    inputs: {in: balls}
  dp:
    type: volume/dimensional_profile
    inputs: {sdf: sdf}
    params: {depth: 64}
  back:
    type: volume/sdf
    inputs: {in: dp}
  half:
    type: volume/sdf
    inputs: {in: dp}
    params: {iso: 0.5}
outputs:
  - {node: back, file: b.vdb}
  - {node: half, file: h.vdb}
)",
                "dp.yaml", std::filesystem::temp_directory_path());
    CookOptions co;
    co.write_outputs = false;
    const CookResult r = s.cook([&] { CookOptions c = co; c.outputs = {"b.vdb"}; return c; }());
    EXPECT_NEAR(r.nodes.at("back").metrics.at("iso"), 2.0 / 255.0, 1e-12);
    const auto truth = as<Field3D>(s.get("sdf", "out", co));
    const auto back = as<Field3D>(s.get("back", "out", co));
    const auto half = as<Field3D>(s.get("half", "out", co));
    const volume::SdfError e = volume::compare_sdf(*back, *truth), e_half = volume::compare_sdf(*half, *truth);
    EXPECT_LT(e.max_abs_voxels, 1.0) << e.max_abs_m << " m";
    EXPECT_GT(e_half.max_abs_m, 24.0) << "iso 0.5 is depth/2 = 32 m inside";
}

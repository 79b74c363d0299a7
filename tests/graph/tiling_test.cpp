// Tiled cooking (atlas/graph/tiling.h): the assembled outputs of 1x1, 2x2 and
// 3x2 tiles are byte-identical to the untiled cook of the same graph (the
// reference is that cook, not stored bytes), tile files hold the crop of the
// untiled value, and bad input is refused naming the tile or node with no
// partial output left.
#include "atlas/graph/tiling.h"

#include "atlas/io/dds_file.h"
#include "atlas/io/readers.h"
#include "atlas/ndf/operators.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>
#include <set>
#include <unistd.h>
#include <sstream>

namespace fs = std::filesystem;
using namespace atlas;

namespace {

const fs::path kWorld = fs::path(ATLAS_SOURCE_DIR) / "tests/graph/tiling/world.yaml";

fs::path scratch_root() { return fs::temp_directory_path() / ("atlas_tiling_" + std::to_string(::getpid())); }

// Removes this process's scratch directories at the end.
struct ScratchCleanup : ::testing::Environment {
    void TearDown() override {
        std::error_code ec;
        fs::remove_all(scratch_root(), ec);
    }
};
const auto* const kCleanup = ::testing::AddGlobalTestEnvironment(new ScratchCleanup);

fs::path scratch(const std::string& name) {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    fs::path d = scratch_root() / (std::string(info->name()) + "_" + name);
    fs::remove_all(d);
    fs::create_directories(d);
    return d;
}

std::string bytes_of(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

// Every regular file under `dir` (relative), without the output records and staging.
std::vector<fs::path> files_under(const fs::path& dir) {
    std::vector<fs::path> v;
    for (const auto& e : fs::recursive_directory_iterator(dir)) {
        if (!e.is_regular_file()) continue;
        const std::string rel = fs::relative(e.path(), dir).generic_string();
        if (rel.find(".atlas-outputs.json") != std::string::npos || rel.find(".atlas-staging") != std::string::npos) continue;
        v.push_back(fs::relative(e.path(), dir));
    }
    std::sort(v.begin(), v.end());
    return v;
}

// Test nodes: a blur that declares too small a halo (the negative control), a
// node without a tiling rule, and a pointwise node that fails away from x = 0.
NodeRegistry registry() {
    NodeRegistry r = builtin_nodes();
    r.add({.name = "test/short_blur", .version = 1,
           .declare = [](NodeDeclaration& d) {
               d.tiling(TileRule::with_halo([](const NodeParams&) { return 0; }));
               d.input("in", PortType::Field2D, "map");
               d.output("out", PortType::Field2D, "blurred");
           },
           .cook = [](CookContext& ctx) {
               ctx.set_output("out", Field2DPtr(std::make_shared<Field2D>(ndf::blur(*ctx.input_field2d("in"), 1.5, WrapMode::Clamp, &ctx.budget()))));
           }});
    r.add({.name = "test/untiled", .version = 1,
           .declare = [](NodeDeclaration& d) {
               d.input("in", PortType::Field2D, "map");
               d.output("out", PortType::Field2D, "the same map");
           },
           .cook = [](CookContext& ctx) { ctx.set_output("out", ctx.input("in")); }});
    r.add({.name = "test/fail_right", .version = 1,
           .declare = [](NodeDeclaration& d) {
               d.tiling(TileRule::pointwise());
               d.input("in", PortType::Field2D, "map");
               d.output("out", PortType::Field2D, "the same map");
           },
           .cook = [](CookContext& ctx) {
               if (ctx.input_field2d("in")->bounds().min[0] > 0) throw Error("fails on purpose right of x = 0");
               ctx.set_output("out", ctx.input("in"));
           }});
    return r;
}

Session load(const fs::path& graph) {
    Session s(registry());
    s.load(graph);
    return s;
}

Session load_text(const std::string& text, const fs::path& dir) {
    Session s(registry());
    s.load_text(text, "inline.yaml", dir);
    return s;
}

CookOptions options(const fs::path& out) {
    CookOptions o;
    o.out_dir = out;
    o.jobs = 2;
    return o;
}

// The message of the atlas::Error a tiled cook throws; a test failure (and "") when it throws none.
std::string tiled_error(Session& s, const CookOptions& o, const TileOptions& t) {
    try {
        cook_tiled(s, o, t);
    } catch (const Error& e) {
        return e.what();
    }
    ADD_FAILURE() << "the tiled cook was accepted";
    return "";
}

const char* kMapHead = R"(atlas: 1
nodes:
  base: { type: ndf/noise, params: { resolution: [32, 32], bounds_min: [0, 0], bounds_max: [3200, 3200], octaves: 3, seed: 1 } }
)";

} // namespace

class TiledCook : public ::testing::TestWithParam<std::pair<int, int>> {};

TEST_P(TiledCook, AssembledFilesAreByteIdenticalToTheUntiledCook) {
    const auto [nx, ny] = GetParam();
    const fs::path single = scratch("single"), tiled = scratch("tiled");
    Session a = load(kWorld);
    const CookResult ra = a.cook(options(single));
    Session b = load(kWorld);
    TileOptions t;
    t.tiles = {{nx, ny}};
    t.assemble = true;
    const TiledCookResult rb = cook_tiled(b, options(tiled), t);
    EXPECT_EQ(rb.grid, (Vec2i{{48, 32}}));
    EXPECT_EQ(rb.tiles_done.size(), size_t(nx * ny));

    const auto files = files_under(single);
    // Every format the graph writes is there: exr (2D, 3D), vdb, dds bc4 and bc1, png, tga slices.
    std::set<std::string> exts;
    for (const auto& f : files) exts.insert(f.extension().string());
    for (const char* e : {".exr", ".vdb", ".dds", ".png", ".tga", ".json"}) EXPECT_TRUE(exts.count(e)) << e;
    ASSERT_GE(files.size(), size_t(16));
    for (const auto& f : files) {
        ASSERT_TRUE(fs::exists(tiled / f)) << f;
        EXPECT_TRUE(bytes_of(single / f) == bytes_of(tiled / f)) << f << " differs between the untiled and the " << nx << "x" << ny << " cook";
    }
    (void)ra;

    // The tile index lists every tile of every output with its files and hashes.
    const auto index = nlohmann::json::parse(bytes_of(tiled / "tiles/index.json"));
    EXPECT_EQ(index["tiles"], nlohmann::json::array({nx, ny}));
    EXPECT_EQ(index["outputs"].size(), size_t(7));
    for (const auto& o : index["outputs"]) {
        ASSERT_EQ(o["tiles"].size(), size_t(nx * ny));
        for (const auto& tile : o["tiles"])
            for (const auto& f : tile["files"]) {
                const fs::path p = tiled / f["path"].get<std::string>();
                ASSERT_TRUE(fs::exists(p)) << p;
                EXPECT_EQ(fs::file_size(p), f["bytes"].get<uint64_t>());
                EXPECT_EQ(file_content_hash(p).hex(), f["hash"].get<std::string>());
            }
    }

    // A tile file holds the crop of the untiled value (read back by the EXR reader).
    const Field2DPtr cover = std::get<Field2DPtr>(a.get("cover", "out"));
    for (const auto& tile : index["outputs"][0]["tiles"]) {
        const auto tx = tile["texels"];
        const fs::path p = tiled / tile["files"][0]["path"].get<std::string>();
        const Value v = io::read_field_file(p);
        const Field2D& f = *std::get<Field2DPtr>(v);
        ASSERT_EQ(f.width(), tx[2].get<int>() - tx[0].get<int>());
        ASSERT_EQ(f.height(), tx[3].get<int>() - tx[1].get<int>());
        for (int y = 0; y < f.height(); ++y)
            for (int x = 0; x < f.width(); ++x) ASSERT_EQ(f.at(0, x, y), cover->at(0, tx[0].get<int>() + x, tx[1].get<int>() + y)) << p;
    }
}

INSTANTIATE_TEST_SUITE_P(Tiles, TiledCook, ::testing::Values(std::pair{1, 1}, std::pair{2, 2}, std::pair{3, 2}));

// The comparison can fail: a blur that declares no halo gives other bytes at
// the tile seams (2x2), and the same bytes untiled (1x1).
TEST(Tiling, TooSmallAHaloChangesTheAssembledBytes) {
    const std::string text = std::string(kMapHead) + R"(  blur: { type: test/short_blur, inputs: { in: base } }
outputs:
  - { node: blur, file: blur.exr }
)";
    const fs::path single = scratch("single");
    Session a = load_text(text, single);
    a.cook(options(single));
    for (int n : {1, 2}) {
        const fs::path tiled = scratch("tiled" + std::to_string(n));
        Session b = load_text(text, tiled);
        TileOptions t;
        t.tiles = {{n, n}};
        t.assemble = true;
        cook_tiled(b, options(tiled), t);
        EXPECT_EQ(bytes_of(single / "blur.exr") == bytes_of(tiled / "blur.exr"), n == 1) << n;
    }
}

TEST(Tiling, NodesThatCannotTileAreRefusedByName) {
    const fs::path out = scratch("out");
    struct Case {
        std::string nodes, expect;
    };
    const std::vector<Case> cases = {
        {"  x: { type: test/untiled, inputs: { in: base } }\n", "node 'x' (test/untiled) cannot be cooked in tiles: its type declares no tiling rule"},
        {"  x: { type: field/resample, inputs: { in: base }, params: { keep_bounds: false, bounds_max: [3200, 3200, 1] } }\n",
         "node 'x' (field/resample) cannot be cooked in tiles: keep_bounds: false changes the grid"},
    };
    for (const auto& c : cases) {
        Session s = load_text(std::string(kMapHead) + c.nodes + "outputs:\n  - { node: x, file: x.exr }\n", out);
        TileOptions t;
        t.tiles = {{2, 2}};
        try {
            cook_tiled(s, options(out), t);
            ADD_FAILURE() << "no error for " << c.nodes;
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find(c.expect), std::string::npos) << e.what();
            EXPECT_NE(std::string(e.what()).find("inline.yaml:"), std::string::npos) << e.what();
        }
        EXPECT_TRUE(files_under(out).empty());
    }
    // An unclipped SDF: Tiling.UnclippedSdfIsRefusedByName.
}

TEST(Tiling, BadTileCountsAndIndicesAreRefused) {
    const fs::path out = scratch("out");
    auto expect_error = [&](Vec2i tiles, std::optional<Vec2i> only, const std::string& expect) {
        Session s = load(kWorld);
        TileOptions t;
        t.tiles = tiles;
        t.only = only;
        try {
            cook_tiled(s, options(out), t);
            ADD_FAILURE() << "no error, expected " << expect;
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find(expect), std::string::npos) << e.what();
        }
        EXPECT_TRUE(files_under(out).empty()) << expect;
    };
    expect_error({{3, 2}}, Vec2i{{3, 0}}, "--tile 3,0 is out of range: --tiles 3,2 has tiles 0..2, 0..1");
    expect_error({{3, 2}}, Vec2i{{0, -1}}, "--tile 0,-1 is out of range");
    expect_error({{5, 2}}, std::nullopt, "does not divide into 5 tiles along x (48 is not a multiple of 5)");
    expect_error({{1, 3}}, std::nullopt, "does not divide into 3 tiles along y");
    // 48 / 8 = 6 texels: not a multiple of the 4x4 BC blocks; the DDS output is named.
    expect_error({{8, 2}}, std::nullopt, "output 'maps/cover_bc4.dds' is BC-compressed in 4x4 blocks, and tiles of 6 x 16 texels are not block-aligned");
    expect_error({{0, 2}}, std::nullopt, "tile counts must be in [1, 4096]");
}

// A tile that fails leaves nothing of itself, no index and no assembled
// output; the tiles before it are complete (each with its fragment).
TEST(Tiling, AFailedTileLeavesNoPartialOutput) {
    const fs::path out = scratch("out");
    Session s = load_text(std::string(kMapHead) + "  x: { type: test/fail_right, inputs: { in: base } }\n"
                                                  "outputs:\n  - { node: x, file: x.exr }\n  - { node: x, file: x.dds, options: { encoding: bc4 } }\n",
                          out);
    TileOptions t;
    t.tiles = {{2, 1}};
    t.assemble = true;
    const std::string what = tiled_error(s, options(out), t);
    EXPECT_NE(what.find("tile 1,0: "), std::string::npos) << what;
    EXPECT_NE(what.find("node 'x' (test/fail_right): fails on purpose"), std::string::npos) << what;
    EXPECT_TRUE(fs::exists(out / "tiles/0_0.json"));
    EXPECT_FALSE(fs::exists(out / "tiles/1_0.json"));
    EXPECT_FALSE(fs::exists(out / "tiles/index.json"));
    EXPECT_FALSE(fs::exists(out / "x.exr"));
    EXPECT_FALSE(fs::exists(out / "x.dds"));
    for (const auto& f : files_under(out)) EXPECT_EQ(f.string().find("1_0"), std::string::npos) << f;
    for (const auto& e : fs::directory_iterator(out)) EXPECT_EQ(e.path().filename().string().find(".atlas-staging"), std::string::npos);
}

// Tiles cooked one by one (as cluster workers do) are reused by the final
// call, which only writes the index and assembles; a damaged tile file makes
// that tile cook again.
TEST(Tiling, TilesCookedSeparatelyAreReusedAndAssembled) {
    const fs::path single = scratch("single"), tiled = scratch("tiled");
    Session a = load(kWorld);
    a.cook(options(single));
    for (int j = 0; j < 2; ++j)
        for (int i = 0; i < 3; ++i) {
            Session b = load(kWorld); // a fresh process per tile
            TileOptions t;
            t.tiles = {{3, 2}};
            t.only = Vec2i{{i, j}};
            const auto r = cook_tiled(b, options(tiled), t);
            ASSERT_EQ(r.tiles_done.size(), size_t(1));
            EXPECT_EQ(r.tiles_done[0].status, "cooked");
            EXPECT_FALSE(fs::exists(tiled / "tiles/index.json"));
        }
    // Damage one tile file: only that tile cooks again.
    {
        const fs::path victim = tiled / "tiles/maps/cover.2_1.exr";
        ASSERT_TRUE(fs::exists(victim));
        std::string bytes = bytes_of(victim);
        bytes[bytes.size() / 2] ^= 1;
        std::ofstream(victim, std::ios::binary | std::ios::trunc) << bytes;
    }
    Session c = load(kWorld);
    TileOptions t;
    t.tiles = {{3, 2}};
    t.assemble = true;
    const auto r = cook_tiled(c, options(tiled), t);
    int cooked = 0;
    for (const auto& tr : r.tiles_done) {
        const bool victim = tr.tile == Vec2i{{2, 1}};
        EXPECT_EQ(tr.status, victim ? "cooked" : "up to date") << tr.tile[0] << "," << tr.tile[1];
        cooked += tr.status == "cooked";
    }
    EXPECT_EQ(cooked, 1);
    for (const auto& f : files_under(single)) EXPECT_TRUE(bytes_of(single / f) == bytes_of(tiled / f)) << f;
}

// Two tiled cooks into one folder never mix (issue 46 item 5): another tiling is refused before
// anything is written; a tile whose files another cook replaced is not assembled from.
TEST(Tiling, AnotherTilingInTheSameFolderIsRefused) {
    const fs::path out = scratch("two_runs");
    Session a = load(kWorld);
    TileOptions t;
    t.tiles = {{2, 2}};
    cook_tiled(a, options(out), t);
    const auto before = files_under(out);
    Session b = load(kWorld);
    t.tiles = {{3, 2}};
    try {
        cook_tiled(b, options(out), t);
        FAIL() << "a 3x2 cook into a folder of 2x2 tiles was accepted";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("holds the tiles of another tiled cook"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("--tiles 2,2"), std::string::npos) << e.what();
    }
    EXPECT_EQ(files_under(out), before);
    // The same tiling into that folder is the cooperating case: accepted (and up to date).
    Session c = load(kWorld);
    t.tiles = {{2, 2}};
    for (const auto& tr : cook_tiled(c, options(out), t).tiles_done) EXPECT_EQ(tr.status, "up to date");
}

// The voxel nodes a cloudscape uses, on uneven splits (issue 46 items 1 and 2): metaballs as a
// windowed generator with its points passed whole, composite of a cloud on a grid of its own and
// of a mesh's SDF (volume/mesh_to_sdf, cooked whole and cropped),
// cutout, erosion and paint at the whole grid's positions, a filter's halo (smooth then dilate),
// the anatomy paint's one-voxel halo and the pointwise NVDF nodes: every assembled byte is the
// untiled cook's.
TEST(Tiling, VoxelCloudscapeNodesTileByteIdentically) {
    const std::string text = R"(atlas: 1
nodes:
  pts: { type: volume/billows, params: { spheres: "1000 1000 256 400; 2600 2000 220 500", levels: 1, children: 6, base_height: 100, seed: 2 } }
  balls:
    type: volume/metaballs
    inputs: { points: pts }
    params: { resolution: [48, 40, 8], bounds_max: [4800, 4000, 512], kernel: sphere, blend: max }
  cloud: { type: volume/metaballs, params: { resolution: [20, 20, 10], bounds_min: [3000, 2500, 0], bounds_max: [4700, 3900, 512], spheres: "3800 3200 250 500" } }
  world: { type: volume/world, params: { resolution: [48, 40, 8], bounds_max: [4800, 4000, 512] } }
  with_balls: { type: volume/composite, inputs: { world: world, cloud: balls } }
  with_cloud: { type: volume/composite, inputs: { world: with_balls, cloud: cloud }, params: { op: add } }
  ring: { type: volume/mesh_primitive, params: { shape: torus, center: [1500, 2800, 250], radius: 700, minor_radius: 150 } }
  ring_sdf: { type: volume/mesh_to_sdf, inputs: { mesh: ring }, params: { resolution: [48, 40, 8], bounds_max: [4800, 4000, 512] } }
  with_ring: { type: volume/composite, inputs: { world: with_cloud, cloud: ring_sdf.density } }
  cut: { type: volume/cutout, inputs: { in: with_ring }, params: { shape: capsule, a: [300, 300, 200], b: [4000, 3000, 300], radius: 150, edge: 60 } }
  eroded: { type: volume/erode_noise, inputs: { in: cut }, params: { amount: 0.3, frequency: 0.003, octaves: 3 } }
  soft: { type: volume/filter, inputs: { in: eroded }, params: { op: smooth, sigma: 1.3 } }
  grown: { type: volume/filter, inputs: { in: soft }, params: { op: dilate, radius: 2 } }
  sdf: { type: volume/sdf, inputs: { in: grown }, params: { iso: 0.3, max_distance: 400 } }
  anatomy: { type: volume/cumulus_paint, inputs: { sdf: sdf }, params: { base_height: 100 } }
  scale: { type: volume/paint, inputs: { like: sdf }, params: { name: density_scale, shape: sphere, a: [2400, 2000, 256], radius: 900, noise_amount: 0.2, noise_frequency: 0.002 } }
  nvdf: { type: volume/nvdf, inputs: { sdf: sdf, detail_type: anatomy.detail_type, density_scale: scale } }
outputs:
  - { node: nvdf, port: vdb_set, file: set.exr }
  - { node: nvdf, port: field_data, file: field.dds, options: { encoding: bc4, range: "0,1" } }
)";
    const fs::path single = scratch("voxel_single");
    Session a = load_text(text, single);
    a.cook(options(single));
    for (const Vec2i tiles : {Vec2i{{3, 2}}, Vec2i{{4, 5}}}) {
        const fs::path tiled = scratch("voxel_tiled_" + std::to_string(tiles[0]) + std::to_string(tiles[1]));
        Session b = load_text(text, tiled);
        TileOptions t;
        t.tiles = tiles;
        t.assemble = true;
        cook_tiled(b, options(tiled), t);
        for (const char* f : {"set.exr", "field.dds", "field.dds.json"})
            EXPECT_TRUE(bytes_of(single / f) == bytes_of(tiled / f)) << f << " at " << tiles[0] << "x" << tiles[1];
    }
}

// Tiles without their exact values (issue 46 item 6): the same tile files, no .atlastile copies,
// and assembling from them is refused up front.
TEST(Tiling, TilesWithoutExactValuesWriteTheSameTileFiles) {
    const fs::path with = scratch("with_values"), without = scratch("without_values");
    TileOptions t;
    t.tiles = {{3, 2}};
    // The world's DDS outputs map by their own range: without exact values their tiles could
    // not be given the world's, so that is refused, naming the output, before any tile cooks.
    t.exact_values = false;
    {
        Session s = load(kWorld);
        const std::string what = tiled_error(s, options(without), t);
        EXPECT_NE(what.find("cover_bc4.dds"), std::string::npos) << what;
        EXPECT_NE(what.find("'range"), std::string::npos) << what;
        EXPECT_FALSE(fs::exists(without / "tiles"));
    }
    // With a stated range they tile.
    std::string text = read_file_bytes(kWorld);
    for (const char* enc : {"encoding: bc4 }", "encoding: bc1 }"}) {
        const size_t at = text.find(enc);
        ASSERT_NE(at, std::string::npos) << enc;
        text.insert(at + std::string(enc).size() - 2, ", range: '0,1'");
    }
    t.exact_values = true;
    Session a = load_text(text, with);
    cook_tiled(a, options(with), t);
    t.exact_values = false;
    Session b = load_text(text, without);
    cook_tiled(b, options(without), t);
    EXPECT_TRUE(fs::exists(with / "tiles/values"));
    EXPECT_FALSE(fs::exists(without / "tiles/values"));
    int compared = 0;
    for (const auto& f : files_under(without)) {
        if (f.extension() == ".json") continue; // fragments and the index name their files
        EXPECT_TRUE(bytes_of(with / f) == bytes_of(without / f)) << f;
        ++compared;
    }
    EXPECT_GT(compared, 20);
    t.assemble = true;
    Session c = load_text(text, without);
    EXPECT_THROW(cook_tiled(c, options(without), t), Error);
}

// Two chains on two grids: the one of the most texels tiles, the other (a chain of its own)
// is cooked whole and written whole, every byte the untiled cook's; a node that reads both
// grids is refused, naming both, before any tile cooks.
TEST(Tiling, AChainOnAGridOfItsOwnIsCookedWhole) {
    const std::string head = R"(atlas: 1
nodes:
  map: { type: ndf/noise, params: { resolution: [16, 16], bounds_max: [4800, 4000], period: [4, 4], seed: 1 } }
  soft: { type: ndf/blur, inputs: { in: map }, params: { sigma: 1.0, tileable: false } }
  vol: { type: noise/perlin_worley, params: { resolution: [48, 40, 4], bounds_max: [4800, 4000, 400], seed: 5 } }
  dens: { type: math/remap, inputs: { in: vol }, params: { in_min: 0.2, in_max: 0.9, clamp: true } }
  lone: { type: noise/perlin_worley, params: { resolution: [24, 20, 4], bounds_max: [4800, 4000, 400], seed: 6 } }
)";
    // `lone`, a windowed generator on a grid of its own that only an output reads, is written whole too.
    const std::string outs = "outputs:\n  - { node: soft, file: soft.exr }\n  - { node: dens, file: dens.exr }\n  - { node: lone, file: lone.exr }\n";
    const fs::path single = scratch("single"), tiled = scratch("tiled");
    Session a = load_text(head + outs, single);
    a.cook(options(single));
    Session b = load_text(head + outs, tiled);
    TileOptions t;
    t.tiles = {{3, 2}};
    t.assemble = true;
    cook_tiled(b, options(tiled), t);
    for (const char* f : {"soft.exr", "dens.exr", "lone.exr"}) EXPECT_TRUE(bytes_of(single / f) == bytes_of(tiled / f)) << f;
    const auto index = nlohmann::json::parse(read_file_bytes(tiled / "tiles/index.json"));
    EXPECT_EQ(index["grid"]["resolution"], nlohmann::json::array({48, 40}));
    for (const auto& o : index["outputs"]) EXPECT_EQ(o.value("whole", false), o["file"] != "dens.exr") << o["file"];
    EXPECT_FALSE(fs::exists(tiled / "tiles/soft.0_0.exr"));
    // A node reading both grids.
    const std::string mixed = head + "  both: { type: math/binary, inputs: { a: dens, b: other }, params: { op: mul } }\n"
                                     "  other: { type: noise/perlin_worley, params: { resolution: [24, 20, 4], bounds_max: [4800, 4000, 400] } }\n"
                                     "outputs:\n  - { node: both, file: both.exr }\n";
    const fs::path refused = scratch("refused");
    Session c = load_text(mixed, refused);
    const std::string what = tiled_error(c, options(refused), t);
    EXPECT_NE(what.find("node 'both'"), std::string::npos) << what;
    EXPECT_NE(what.find("24 x 20"), std::string::npos) << what;
    EXPECT_NE(what.find("48 x 40"), std::string::npos) << what;
    EXPECT_FALSE(fs::exists(refused / "tiles"));
}

// A halo wider than a tile is exact but costly: the cook says so, naming the node, and the
// report carries it; a halo within a tile says nothing.
TEST(Tiling, AHaloWiderThanATileIsSaid) {
    auto text = [](int max_distance) {
        return std::string(R"(atlas: 1
nodes:
  vol: { type: noise/perlin_worley, params: { resolution: [48, 40, 4], bounds_max: [4800, 4000, 400], seed: 5 } }
  sdf: { type: volume/sdf, inputs: { in: vol }, params: { iso: 0.6, max_distance: )") + std::to_string(max_distance) + R"( } }
outputs:
  - { node: sdf, file: sdf.exr }
)";
    };
    TileOptions t;
    t.tiles = {{3, 2}}; // tiles of 16 x 20 voxels of 100 m
    for (const int d : {500, 3000}) {
        const fs::path out = scratch("halo" + std::to_string(d));
        Session s = load_text(text(d), out);
        TiledCookResult r;
        cook_tiled(s, options(out), t, r);
        const auto doc = nlohmann::json::parse(tiled_report_json(r, "inline.yaml", "ok", ""));
        if (d == 500) {
            EXPECT_TRUE(r.warnings.empty()) << r.warnings.front();
            EXPECT_FALSE(doc.contains("warnings"));
        } else {
            ASSERT_EQ(r.warnings.size(), 1u);
            EXPECT_NE(r.warnings[0].find("node 'sdf' (volume/sdf): its tiling halo of 31 texels is wider than a tile (16 x 20)"), std::string::npos)
                << r.warnings[0];
            EXPECT_EQ(doc["warnings"][0], r.warnings[0]);
        }
    }
}

// A DDS without 'range' maps its values by their own min and max. Each tile's texture
// quantises as the whole world's does (its blocks are the untiled texture's blocks, byte for
// byte), the index states the world's range, and a second cook rewrites nothing.
TEST(Tiling, TileTexturesQuantiseAsTheWorldDoes) {
    const fs::path single = scratch("single"), tiled = scratch("tiled");
    Session a = load(kWorld);
    a.cook(options(single));
    TileOptions t;
    t.tiles = {{3, 2}};
    Session b = load(kWorld);
    cook_tiled(b, options(tiled), t);
    const auto index = nlohmann::json::parse(read_file_bytes(tiled / "tiles/index.json"));
    int blocks = 0;
    for (const char* name : {"cover_bc4", "rgb_bc1"}) {
        const compress::DdsTexture whole = io::read_dds_file(single / "maps" / (std::string(name) + ".dds"));
        const auto manifest = io::read_dds_manifest(single / "maps" / (std::string(name) + ".dds"));
        ASSERT_TRUE(manifest);
        bool listed = false;
        for (const auto& o : index["outputs"])
            if (o["file"] == std::string("maps/") + name + ".dds") {
                listed = true;
                EXPECT_EQ(o["range"], nlohmann::json::array({manifest->range_lo, manifest->range_hi})) << name;
            }
        EXPECT_TRUE(listed) << name;
        const int bpb = int(compress::level_bytes(whole.format, 4, 4, 1)); // bytes per 4x4 block
        const int wide = whole.width / 4;
        for (int j = 0; j < 2; ++j)
            for (int i = 0; i < 3; ++i) {
                const TileRect r = tile_rect({{48, 32}}, {{3, 2}}, {{i, j}});
                const fs::path p = tiled / "tiles/maps" / (std::string(name) + "." + std::to_string(i) + "_" + std::to_string(j) + ".dds");
                const compress::DdsTexture tile = io::read_dds_file(p);
                ASSERT_EQ(tile.format, whole.format);
                ASSERT_EQ(tile.width, r.width());
                // DDS rows run top-down: the tile's block row 0 holds field rows [y1 - 4, y1).
                for (int by = 0; by < r.height() / 4; ++by)
                    for (int bx = 0; bx < r.width() / 4; ++bx) {
                        const size_t wb = size_t((32 - r.y1) / 4 + by) * size_t(wide) + size_t(r.x0 / 4 + bx);
                        const size_t tb = size_t(by) * size_t(r.width() / 4) + size_t(bx);
                        ASSERT_TRUE(std::equal(tile.data.begin() + long(tb) * bpb, tile.data.begin() + long(tb + 1) * bpb,
                                               whole.data.begin() + long(wb) * bpb))
                            << p << " block " << bx << "," << by;
                        ++blocks;
                    }
            }
    }
    EXPECT_EQ(blocks, 2 * 12 * 8);
    // A second cook finds every tile on the world's range: nothing is written.
    Session c = load(kWorld);
    TiledCookResult again;
    cook_tiled(c, options(tiled), t, again);
    EXPECT_TRUE(again.written.empty()) << again.written.size() << " files, the first " << again.written.front();
}

// Every noise kernel fills each tile's window itself (2D and 3D, a
// non-integer frequency and an offset, tiles of 10 texels): the assembled
// bytes are the untiled cook's.
TEST(Tiling, WindowedNoiseKernelsAreBitIdentical) {
    std::string text = "atlas: 1\nnodes:\n";
    std::string outs = "outputs:\n";
    const char* grid = "resolution: [30, 20, 4], bounds_min: [-100, 50, 0], bounds_max: [2900, 2050, 400]";
    for (const char* k : {"perlin_worley", "worley", "curl", "alligator", "curly_alligator", "gradient"}) {
        text += std::string("  ") + k + ": { type: noise/" + k + ", params: { " + grid + ", frequency: 1.5, offset: [0.25, 0.5, 0], octaves: 3, seed: 9 } }\n";
        outs += std::string("  - { node: ") + k + ", file: " + k + ".exr }\n";
    }
    text += std::string("  flat: { type: noise/worley, params: { dimensions: 2d, ") + grid + ", octaves: 2 } }\n";
    text += std::string("  norm: { type: noise/gradient, params: { ") + grid + ", normalize: true } }\n";
    outs += "  - { node: flat, file: flat.exr }\n  - { node: norm, file: norm.exr }\n";
    const fs::path single = scratch("single"), tiled = scratch("tiled");
    Session a = load_text(text + outs, single);
    a.cook(options(single));
    Session b = load_text(text + outs, tiled);
    TileOptions t;
    t.tiles = {{3, 2}};
    t.assemble = true;
    cook_tiled(b, options(tiled), t);
    const auto files = files_under(single);
    ASSERT_EQ(files.size(), size_t(8));
    for (const auto& f : files) EXPECT_TRUE(bytes_of(single / f) == bytes_of(tiled / f)) << f;
}

// A windowed generator never makes its whole grid: under a memory budget
// smaller than the whole field (which the untiled cook is refused), the tiles
// cook, and each tile file holds the crop of the untiled value.
TEST(Tiling, WindowedGeneratorsStayWithinATilesMemory) {
    const std::string text = R"(atlas: 1
nodes:
  n: { type: noise/perlin_worley, params: { resolution: [64, 64, 16], bounds_max: [6400, 6400, 1600], seed: 2 } }
  d: { type: math/remap, inputs: { in: n }, params: { in_min: 0.3, in_max: 0.8 } }
outputs:
  - { node: d, file: d.exr }
)";
    const uint64_t whole = 64ull * 64 * 16 * 4, tile = whole / 4;
    const fs::path single = scratch("single"), tiled = scratch("tiled");
    CookOptions small = options(single);
    small.memory_budget = tile + tile / 2;
    Session a = load_text(text, single);
    EXPECT_THROW(a.cook(small), MemoryBudgetError);
    const Field3DPtr ref = std::get<Field3DPtr>(a.get("d", "out"));
    Session b = load_text(text, tiled);
    TileOptions t;
    t.tiles = {{2, 2}};
    CookOptions o = options(tiled);
    o.memory_budget = tile + tile / 2;
    cook_tiled(b, o, t);
    for (int j = 0; j < 2; ++j)
        for (int i = 0; i < 2; ++i) {
            const fs::path p = tiled / ("tiles/d." + std::to_string(i) + "_" + std::to_string(j) + ".exr");
            const Field3DPtr f = io::as_field3d(io::read_field_file(p));
            ASSERT_EQ(f->resolution(), (Vec3i{{32, 32, 16}}));
            for (int z = 0; z < 16; ++z)
                for (int y = 0; y < 32; ++y)
                    for (int x = 0; x < 32; ++x) ASSERT_EQ(f->at(0, x, y, z), ref->at(0, 32 * i + x, 32 * j + y, z)) << p;
        }
    // Assembling the whole field under that budget is refused before it is allocated; the
    // message says the tiles and their index are the product, and they stay as they were.
    const std::string index_before = read_file_bytes(tiled / "tiles/index.json");
    t.assemble = true;
    Session c = load_text(text, tiled);
    try {
        cook_tiled(c, o, t);
        ADD_FAILURE() << "assembling past the memory budget was accepted";
    } catch (const MemoryBudgetError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("assembling output 'd.exr'"), std::string::npos) << what;
        EXPECT_NE(what.find("index.json' are written and complete"), std::string::npos) << what;
    }
    EXPECT_FALSE(fs::exists(tiled / "d.exr"));
    EXPECT_EQ(read_file_bytes(tiled / "tiles/index.json"), index_before);
}

// ------------------------------------------------------------ clipped SDFs

namespace {

const fs::path kSdfWorld = fs::path(ATLAS_SOURCE_DIR) / "tests/graph/tiling/sdf_world.yaml";

// Brute force, independent of the EDT: the distance (metres) from voxel
// (x, y, z)'s centre to the nearest linear iso crossing on any grid edge (and
// to the grid faces half a voxel beyond the border voxels, when `faces`),
// clipped to `clip`, negative inside (density > iso).
double brute_sdf(const Field3D& d, double iso, double clip, bool faces, int x, int y, int z) {
    const Vec3d h = d.voxel_size();
    const Vec3i res = d.resolution();
    double best = clip * clip;
    auto consider = [&](double px, double py, double pz) {
        const double dx = (px - x) * h[0], dy = (py - y) * h[1], dz = (pz - z) * h[2];
        best = std::min(best, dx * dx + dy * dy + dz * dz);
    };
    for (int k = 0; k < res[2]; ++k)
        for (int j = 0; j < res[1]; ++j)
            for (int i = 0; i < res[0]; ++i) {
                const float a = d.at(0, i, j, k);
                const bool in = a > iso;
                const int c[3] = {i, j, k};
                for (int axis = 0; axis < 3; ++axis) {
                    double p[3] = {double(i), double(j), double(k)};
                    if (faces && in && c[axis] == 0) {
                        p[axis] -= 0.5;
                        consider(p[0], p[1], p[2]);
                        p[axis] += 0.5;
                    }
                    if (faces && in && c[axis] == res[axis] - 1) {
                        p[axis] += 0.5;
                        consider(p[0], p[1], p[2]);
                        p[axis] -= 0.5;
                    }
                    if (c[axis] + 1 >= res[axis]) continue;
                    const int n[3] = {i + (axis == 0), j + (axis == 1), k + (axis == 2)};
                    const float b = d.at(0, n[0], n[1], n[2]);
                    if ((b > iso) == in) continue;
                    p[axis] += (iso - double(a)) / (double(b) - double(a));
                    consider(p[0], p[1], p[2]);
                }
            }
    const double dist = std::sqrt(best);
    return d.at(0, x, y, z) > iso ? -dist : dist;
}

} // namespace

class TiledSdf : public ::testing::TestWithParam<std::pair<int, int>> {};

// A clipped SDF tiles: the assembled EXR, VDB, TGA slices and BC4 DDS are the
// untiled cook's bytes, for a clip below and above the tile size; and the
// assembled distances are the brute-force distances of the density.
TEST_P(TiledSdf, AssembledClippedSdfIsByteIdenticalToTheUntiledCook) {
    const auto [nx, ny] = GetParam();
    const fs::path single = scratch("single"), tiled = scratch("tiled");
    Session a = load(kSdfWorld);
    a.cook(options(single));
    Session b = load(kSdfWorld);
    TileOptions t;
    t.tiles = {{nx, ny}};
    t.assemble = true;
    const TiledCookResult rb = cook_tiled(b, options(tiled), t);
    EXPECT_EQ(rb.tiles_done.size(), size_t(nx * ny));
    const auto files = files_under(single);
    std::set<std::string> exts;
    for (const auto& f : files) exts.insert(f.extension().string());
    for (const char* e : {".exr", ".vdb", ".dds", ".tga"}) EXPECT_TRUE(exts.count(e)) << e;
    ASSERT_GE(files.size(), size_t(14));
    for (const auto& f : files) {
        ASSERT_TRUE(fs::exists(tiled / f)) << f;
        EXPECT_TRUE(bytes_of(single / f) == bytes_of(tiled / f)) << f << " differs between the untiled and the " << nx << "x" << ny << " cook";
    }

    // The assembled distances against brute force, at voxels near the tile
    // seams and corners and elsewhere (both clips reach across seams).
    const Field3DPtr dens = std::get<Field3DPtr>(a.get("dens", "out"));
    const Field3DPtr near = io::as_field3d(io::read_field_file(tiled / "near.vdb"));
    const Field3DPtr far = io::as_field3d(io::read_field_file(tiled / "far.vdb"));
    ASSERT_EQ(near->resolution(), dens->resolution());
    int surface = 0, clipped = 0;
    for (int x : {0, 7, 15, 16, 23, 24, 31, 32, 47})
        for (int y : {0, 9, 15, 16, 31})
            for (int z : {0, 3, 7}) {
                const double bn = brute_sdf(*dens, 0.5, 350, false, x, y, z);
                const double bf = brute_sdf(*dens, 0.6, 2500, true, x, y, z);
                EXPECT_NEAR(near->at(0, x, y, z), bn, 1e-3) << x << "," << y << "," << z;
                EXPECT_NEAR(far->at(0, x, y, z), bf, 1e-2) << x << "," << y << "," << z;
                surface += std::abs(bn) < 350;
                clipped += std::abs(bn) == 350;
            }
    // The sample sees both distances within the clip and clipped ones.
    EXPECT_GT(surface, 20);
    EXPECT_GT(clipped, 0);
}

INSTANTIATE_TEST_SUITE_P(Tiles, TiledSdf, ::testing::Values(std::pair{1, 1}, std::pair{2, 2}, std::pair{3, 2}));

// An unclipped SDF (and fast sweeping) is refused for tiling, naming the node
// and saying what to set; a clip on the same graph is accepted.
TEST(Tiling, UnclippedSdfIsRefusedByName) {
    const fs::path out = scratch("out");
    const std::string head = R"(atlas: 1
nodes:
  vol: { type: noise/perlin_worley, params: { resolution: [32, 32, 4], bounds_max: [3200, 3200, 400], seed: 5 } }
)";
    struct Case {
        std::string sdf, expect;
    };
    const std::vector<Case> cases = {
        {"{}", "node 'dist' (volume/sdf) cannot be cooked in tiles: an exact distance transform of unclipped distances reads the whole grid"},
        {"{ method: fast_sweeping, max_distance: 300 }", "node 'dist' (volume/sdf) cannot be cooked in tiles: method 'fast_sweeping'"},
    };
    for (const auto& c : cases) {
        Session s = load_text(head + "  dist: { type: volume/sdf, inputs: { in: vol }, params: " + c.sdf + " }\noutputs:\n  - { node: dist, file: d.exr }\n", out);
        TileOptions t;
        t.tiles = {{2, 2}};
        try {
            cook_tiled(s, options(out), t);
            ADD_FAILURE() << "no error for " << c.sdf;
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find(c.expect), std::string::npos) << e.what();
            EXPECT_NE(std::string(e.what()).find("inline.yaml:"), std::string::npos) << e.what();
            if (c.sdf == "{}") {
                EXPECT_NE(std::string(e.what()).find("set 'max_distance'"), std::string::npos) << e.what();
            }
        }
        EXPECT_TRUE(files_under(out).empty());
    }
    Session ok = load_text(head + "  dist: { type: volume/sdf, inputs: { in: vol }, params: { max_distance: 300 } }\noutputs:\n  - { node: dist, file: d.exr }\n", out);
    EXPECT_NO_THROW(check_tileable(ok, {}));
}

// The halo is what makes the tiles exact: the same clipped SDF with its halo
// forced to 0 (a test node wrapping volume/sdf) gives other bytes at the
// seams, so the comparison above can fail.
TEST(Tiling, ClippedSdfWithoutItsHaloDiffersAtTheSeams) {
    const std::string text = R"(atlas: 1
nodes:
  vol:  { type: noise/perlin_worley, params: { resolution: [32, 32, 4], bounds_max: [3200, 3200, 400], seed: 5 } }
  dens: { type: math/remap, inputs: { in: vol }, params: { in_min: 0.2, in_max: 0.9 } }
  dist: { type: volume/sdf, inputs: { in: dens }, params: { max_distance: 400 } }
outputs:
  - { node: dist, file: d.vdb }
)";
    const fs::path single = scratch("single"), tiled = scratch("tiled"), zero = scratch("zero");
    Session a = load_text(text, single);
    a.cook(options(single));
    TileOptions t;
    t.tiles = {{2, 2}};
    t.assemble = true;
    Session b = load_text(text, tiled);
    cook_tiled(b, options(tiled), t);
    EXPECT_TRUE(bytes_of(single / "d.vdb") == bytes_of(tiled / "d.vdb"));
    // volume/sdf re-declared with a zero halo (keeping the window, so only the halo differs).
    NodeRegistry r = builtin_nodes();
    const NodeType* sdf = r.find("volume/sdf");
    r.add({.name = "test/sdf_no_halo", .version = 1,
           .declare =
               [declare = sdf->declare](NodeDeclaration& d) {
                   declare(d);
                   d.tiling(TileRule::with_halo([](const NodeParams&) { return 0; }).with_window());
               },
           .cook = sdf->cook});
    Session c(std::move(r));
    std::string text0 = text;
    text0.replace(text0.find("type: volume/sdf"), 16, "type: test/sdf_no_halo");
    c.load_text(text0, "inline.yaml", zero);
    cook_tiled(c, options(zero), t);
    EXPECT_FALSE(bytes_of(single / "d.vdb") == bytes_of(zero / "d.vdb"));
}

// The tiled cook's report (docs/report.md, "Tiled cooks"): per tile its
// status, times, memory and files, whose sizes and hashes are those on disk;
// after a failure it still lists the tiles done and the failed tile.
TEST(Tiling, ReportListsEveryTileAndTheFailedOne) {
    const fs::path out = scratch("out");
    {
        Session s = load(kWorld);
        TileOptions t;
        t.tiles = {{3, 2}};
        t.assemble = true;
        TiledCookResult r;
        cook_tiled(s, options(out), t, r);
        const auto doc = nlohmann::json::parse(tiled_report_json(r, "world.yaml", "ok", ""));
        EXPECT_EQ(doc["status"], "ok");
        EXPECT_EQ(doc["tiled"]["tiles"], nlohmann::json::array({3, 2}));
        EXPECT_EQ(doc["tiled"]["grid"], nlohmann::json::array({48, 32}));
        ASSERT_EQ(doc["tiles"].size(), size_t(6));
        EXPECT_EQ(doc["tiles"][1]["tile"], nlohmann::json::array({1, 0})); // row by row
        EXPECT_EQ(doc["summary"]["cooked"], 6);
        EXPECT_EQ(doc["assembled"].size(), files_under(out).size() - files_under(out / "tiles").size());
        for (const auto& tile : doc["tiles"]) {
            EXPECT_EQ(tile["status"], "cooked");
            EXPECT_GT(tile["value_bytes_peak"].get<uint64_t>(), uint64_t(48 / 3 * 32 / 2 * 8 * 4)); // at least the tile's density
            EXPECT_GE(tile["rss_peak_bytes"].get<uint64_t>(), tile["value_bytes_peak"].get<uint64_t>());
            EXPECT_GE(tile["files"].size(), size_t(7 + 1));
            for (const auto& f : tile["files"]) {
                const fs::path p = out / f["path"].get<std::string>();
                ASSERT_TRUE(fs::exists(p)) << p;
                EXPECT_EQ(fs::file_size(p), f["bytes"].get<uint64_t>()) << p;
                EXPECT_EQ(file_content_hash(p).hex(), f["hash"].get<std::string>()) << p;
            }
        }
        // A second call finds every tile up to date.
        Session s2 = load(kWorld);
        TiledCookResult r2;
        cook_tiled(s2, options(out), t, r2);
        const auto doc2 = nlohmann::json::parse(tiled_report_json(r2, "world.yaml", "ok", ""));
        EXPECT_EQ(doc2["summary"]["up to date"], 6);
        EXPECT_EQ(doc2["tiles"][0]["files"], doc["tiles"][0]["files"]);
    }
    const fs::path bad = scratch("bad");
    Session s = load_text(std::string(kMapHead) + "  x: { type: test/fail_right, inputs: { in: base } }\noutputs:\n  - { node: x, file: x.exr }\n", bad);
    TileOptions t;
    t.tiles = {{2, 1}};
    TiledCookResult r;
    std::string error;
    try {
        cook_tiled(s, options(bad), t, r);
    } catch (const Error& e) {
        error = e.what();
    }
    ASSERT_FALSE(error.empty());
    const auto doc = nlohmann::json::parse(tiled_report_json(r, "inline.yaml", "failed", error));
    EXPECT_EQ(doc["status"], "failed");
    EXPECT_EQ(doc["error"]["tile"], nlohmann::json::array({1, 0}));
    ASSERT_EQ(doc["tiles"].size(), size_t(2));
    EXPECT_EQ(doc["tiles"][0]["status"], "cooked");
    EXPECT_EQ(doc["tiles"][1]["status"], "failed");
    EXPECT_NE(doc["tiles"][1]["error"].get<std::string>().find("fails on purpose"), std::string::npos);
    EXPECT_TRUE(doc["tiles"][1]["files"].empty());
    EXPECT_EQ(doc["summary"]["failed"], 1);
    EXPECT_FALSE(doc.contains("index"));
}

// Tileable blur and warp wrap around the world, not the tile: their halo is the whole map, so
// every tile computes them over the whole map (exact; the cook says the halo is wider than a
// tile), and the assembled bytes are the untiled cook's.
TEST(Tiling, TileableBlurAndWarpWrapAcrossTheWorld) {
    const std::string text = R"(atlas: 1
nodes:
  base: { type: ndf/noise, params: { resolution: [48, 32], bounds_min: [0, 0], bounds_max: [4800, 3200], period: [4, 4], octaves: 3, seed: 1 } }
  push: { type: ndf/noise, params: { resolution: [48, 32], bounds_min: [0, 0], bounds_max: [4800, 3200], period: [3, 3], octaves: 2, seed: 4 } }
  soft: { type: ndf/blur, inputs: { in: base }, params: { sigma: 2.5 } }
  bent: { type: ndf/warp, inputs: { in: soft, warp: push }, params: { amount: 600 } }
outputs:
  - { node: soft, file: soft.exr }
  - { node: bent, file: bent.exr }
)";
    const fs::path single = scratch("single");
    Session a = load_text(text, single);
    a.cook(options(single));
    // Wrapped: the left column's blur reads the right edge (it differs from the clamped blur there).
    const Field2DPtr soft = std::get<Field2DPtr>(a.get("soft", "out"));
    const Field2D clamped = ndf::blur(*std::get<Field2DPtr>(a.get("base", "out")), 2.5, WrapMode::Clamp, nullptr);
    EXPECT_NE(soft->at(0, 0, 10), clamped.at(0, 0, 10));
    for (auto [nx, ny] : {std::pair{2, 2}, std::pair{3, 2}}) {
        const fs::path tiled = scratch("tiled" + std::to_string(nx) + std::to_string(ny));
        Session b = load_text(text, tiled);
        TileOptions t;
        t.tiles = {{nx, ny}};
        t.assemble = true;
        TiledCookResult r;
        cook_tiled(b, options(tiled), t, r);
        for (const char* f : {"soft.exr", "bent.exr"}) EXPECT_TRUE(bytes_of(single / f) == bytes_of(tiled / f)) << f << " " << nx << "x" << ny;
        ASSERT_EQ(r.warnings.size(), 2u);
        EXPECT_NE(r.warnings[0].find("node 'soft' (ndf/blur): its tiling halo of 48 texels is wider than a tile"), std::string::npos) << r.warnings[0];
    }
}

// ndf/warp (tileable: false) tiles with a halo of its largest offset: the
// assembled EXR and BC4 DDS are the untiled bytes, for an offset below and
// above the tile size; a warp value outside [0, 1] (an offset beyond the
// halo) is refused in a tiled cook, naming the node.
TEST(Tiling, WarpTilesWithTheHaloOfItsLargestOffset) {
    const std::string text = R"(atlas: 1
nodes:
  base: { type: ndf/noise, params: { resolution: [48, 32], bounds_min: [0, 0], bounds_max: [4800, 3200], octaves: 3, seed: 1 } }
  push: { type: ndf/noise, params: { resolution: [48, 32], bounds_min: [0, 0], bounds_max: [4800, 3200], period: [3, 3], octaves: 2, seed: 4 } }
  near: { type: ndf/warp, inputs: { in: base, warp: push }, params: { amount: 280, tileable: false } }
  far:  { type: ndf/warp, inputs: { in: base, warp: push }, params: { amount: 2100, tileable: false } }
outputs:
  - { node: near, file: near.exr }
  - { node: near, file: near_bc4.dds, options: { encoding: bc4 } }
  - { node: far, file: far.exr }
)";
    const fs::path single = scratch("single");
    Session a = load_text(text, single);
    a.cook(options(single));
    // The untiled node is the library's domain warp.
    const Field2D ref = ndf::domain_warp(*std::get<Field2DPtr>(a.get("base", "out")), *std::get<Field2DPtr>(a.get("push", "out")), 280,
                                         WrapMode::Clamp, nullptr);
    const Field2DPtr near = std::get<Field2DPtr>(a.get("near", "out"));
    ASSERT_EQ(near->resolution(), ref.resolution());
    for (int y = 0; y < 32; ++y)
        for (int x = 0; x < 48; ++x) ASSERT_EQ(near->at(0, x, y), ref.at(0, x, y));
    for (auto [nx, ny] : {std::pair{1, 1}, std::pair{2, 2}, std::pair{3, 2}}) {
        const fs::path tiled = scratch("tiled" + std::to_string(nx) + std::to_string(ny));
        Session b = load_text(text, tiled);
        TileOptions t;
        t.tiles = {{nx, ny}};
        t.assemble = true;
        cook_tiled(b, options(tiled), t);
        const auto files = files_under(single);
        ASSERT_EQ(files.size(), size_t(4));
        for (const auto& f : files) EXPECT_TRUE(bytes_of(single / f) == bytes_of(tiled / f)) << f << " " << nx << "x" << ny;
    }
    // Offsets beyond the halo: a warp value of 1.5.
    const fs::path bad = scratch("bad");
    Session c = load_text(R"(atlas: 1
nodes:
  base: { type: ndf/noise, params: { resolution: [32, 32], bounds_min: [0, 0], bounds_max: [3200, 3200], seed: 1 } }
  push: { type: ndf/constant, params: { resolution: [32, 32], bounds_max: [3200, 3200], value: 1.5 } }
  x: { type: ndf/warp, inputs: { in: base, warp: push }, params: { amount: 200, tileable: false } }
outputs:
  - { node: x, file: x.exr }
)",
                          bad);
    TileOptions t;
    t.tiles = {{2, 2}};
    try {
        cook_tiled(c, options(bad), t);
        ADD_FAILURE() << "no error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("tile 0,0: "), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("node 'x' (ndf/warp)"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("outside [0, 1]"), std::string::npos) << e.what();
    }
    EXPECT_TRUE(files_under(bad).empty());
}

// field/resample tiles when it keeps the XY grid (z only, and a 2D identity; with wrap: wrap
// its halo is the whole grid): the assembled bytes are the untiled cook's; a new XY resolution fails the
// tile naming the node, and keep_bounds: false is refused.
TEST(Tiling, ResampleOfZOnlyTiles) {
    const std::string head = R"(atlas: 1
nodes:
  vol:  { type: noise/perlin_worley, params: { resolution: [48, 32, 8], bounds_min: [-30, 10, 0], bounds_max: [4770, 3210, 800], seed: 5 } }
  base: { type: ndf/noise, params: { resolution: [48, 32], bounds_min: [-30, 10], bounds_max: [4770, 3210], octaves: 3, seed: 1 } }
)";
    const std::string text = head + R"(  fine: { type: field/resample, inputs: { in: vol }, params: { resolution: [48, 32, 13] } }
  flat: { type: field/resample, inputs: { in: base }, params: { resolution: [48, 32, 1] } }
  wrapped: { type: field/resample, inputs: { in: vol }, params: { resolution: [48, 32, 5], wrap: wrap } }
outputs:
  - { node: fine, file: fine.vdb }
  - { node: fine, file: fine.exr }
  - { node: flat, file: flat.exr }
  - { node: wrapped, file: wrapped.exr }
)";
    const fs::path single = scratch("single");
    Session a = load_text(text, single);
    a.cook(options(single));
    EXPECT_EQ(std::get<Field3DPtr>(a.get("fine", "out"))->nz(), 13);
    for (auto [nx, ny] : {std::pair{1, 1}, std::pair{2, 2}, std::pair{3, 2}}) {
        const fs::path tiled = scratch("tiled" + std::to_string(nx) + std::to_string(ny));
        Session b = load_text(text, tiled);
        TileOptions t;
        t.tiles = {{nx, ny}};
        t.assemble = true;
        cook_tiled(b, options(tiled), t);
        const auto files = files_under(single);
        ASSERT_EQ(files.size(), size_t(4));
        for (const auto& f : files) EXPECT_TRUE(bytes_of(single / f) == bytes_of(tiled / f)) << f << " " << nx << "x" << ny;
    }
    const fs::path bad = scratch("bad");
    for (const auto& [params, expect] : {std::pair<std::string, std::string>{"{ resolution: [24, 32, 8] }", "needs the XY resolution kept (48 x 32)"},
                                         {"{ resolution: [48, 32, 8], keep_bounds: false, bounds_max: [10, 10, 10] }", "keep_bounds: false"}}) {
        Session c = load_text(head + "  x: { type: field/resample, inputs: { in: vol }, params: " + params + " }\noutputs:\n  - { node: x, file: x.exr }\n", bad);
        TileOptions t;
        t.tiles = {{2, 2}};
        try {
            cook_tiled(c, options(bad), t);
            ADD_FAILURE() << "no error for " << params;
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find("node 'x' (field/resample)"), std::string::npos) << e.what();
            EXPECT_NE(std::string(e.what()).find(expect), std::string::npos) << e.what();
        }
        EXPECT_TRUE(files_under(bad).empty());
    }
}

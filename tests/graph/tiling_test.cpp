// Tiled cooking (atlas/graph/tiling.h): the assembled outputs of 1x1, 2x2 and
// 3x2 tiles are byte-identical to the untiled cook of the same graph (the
// reference is that cook, not stored bytes), tile files hold the crop of the
// untiled value, and bad input is refused naming the tile or node with no
// partial output left.
#include "atlas/graph/tiling.h"

#include "atlas/io/readers.h"
#include "atlas/ndf/operators.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

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
        {"  w: { type: ndf/constant, params: { resolution: [32, 32], bounds_max: [3200, 3200], value: 0.5 } }\n"
         "  x: { type: ndf/warp, inputs: { in: base, warp: w } }\n",
         "node 'x' (ndf/warp) cannot be cooked in tiles"},
        {"  x: { type: ndf/blur, inputs: { in: base } }\n", "node 'x' (ndf/blur) cannot be cooked in tiles: tileable: true wraps"},
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
    // The SDF: an exact distance transform is refused, not approximated.
    const NodeRegistry reg = builtin_nodes();
    const TileRule& sdf = reg.find("volume/sdf")->decl.tiling();
    EXPECT_EQ(sdf.kind, TileRule::Kind::None);
    EXPECT_NE(sdf.why_not.find("exact distance transform"), std::string::npos);
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
    try {
        cook_tiled(s, options(out), t);
        ADD_FAILURE() << "no error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("tile 1,0: "), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("node 'x' (test/fail_right): fails on purpose"), std::string::npos) << e.what();
    }
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
}

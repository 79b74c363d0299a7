// graphs/superstorm.yaml writes the vortex-ring JSON sidecar through the `json` output format.
#include "atlas/core/files.h"
#include "atlas/graph/evaluator.h"
#include "atlas/graph/node.h"
#include "atlas/ndf/superstorm.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>

using namespace atlas;

TEST(NdfGraphs, SuperstormWritesTheVortexRingSidecar) {
    namespace fs = std::filesystem;
    const fs::path dir = fs::path(ATLAS_SOURCE_DIR) / "graphs";
    const fs::path out = fs::temp_directory_path() / ("atlas_superstorm_sidecar_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()));
    fs::remove_all(out);
    fs::create_directories(out);
    Session s(builtin_nodes());
    s.load_text(read_file_bytes(dir / "superstorm.yaml"), "superstorm.yaml", dir);
    CookOptions co;
    co.out_dir = out;
    co.outputs = {"vortex_rings.json"};
    s.cook(co);
    const auto j = nlohmann::json::parse(read_file_bytes(out / "vortex_rings.json"));
    fs::remove_all(out);
    // The graph's parameters: centre (12000, 20000), radius 7000, 6 even rings, overlap 0.3, speed 0.05, skew 0.4.
    const auto rings = ndf::make_vortex_rings(7000, 6, {}, 0.3, 0.05, 0.4);
    EXPECT_DOUBLE_EQ(j.at("center").at(0).get<double>(), 12000.0);
    EXPECT_DOUBLE_EQ(j.at("center").at(1).get<double>(), 20000.0);
    EXPECT_DOUBLE_EQ(j.at("bounds").at("max").at(0).get<double>() - j.at("center").at(0).get<double>(), 7000.0); // radius
    ASSERT_EQ(j.at("rows").size(), rings.size());
    for (size_t i = 0; i < rings.size(); ++i) {
        const auto& row = j.at("rows").at(i);
        const auto& r = rings[i];
        EXPECT_EQ(row.at("x").get<int>(), int(i));
        EXPECT_EQ(row.at("inner").get<float>(), float(r.inner));
        EXPECT_EQ(row.at("outer").get<float>(), float(r.outer));
        EXPECT_EQ(row.at("speed").get<float>(), float(r.speed));
        EXPECT_EQ(row.at("skew").get<float>(), float(r.skew));
        EXPECT_EQ(row.at("overlap_end").get<float>(), float(r.outer + 0.3 * (r.outer - r.inner)));
        if (i) {
            EXPECT_LT(row.at("speed").get<float>(), j.at("rows").at(i - 1).at("speed").get<float>());
        }
    }
}

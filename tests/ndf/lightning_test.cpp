// The lightning schedule (000, "Lightning Effects"): windows that tile time agree, the rate,
// the sequence's shape, placement in the storm, bad input, and the lifecycle graph's schedule.
#include "atlas/ndf/lightning.h"

#include "atlas/core/error.h"
#include "atlas/graph/evaluator.h"
#include "atlas/graph/node.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <map>

using namespace atlas;
using namespace atlas::ndf;

namespace {
// A 32x32 set over 32 km: a storm in the square [8, 16) x [20, 28) of texels, base 800 m, top 12 km.
Field2D storm_set() {
    Field2D s({{32, 32}}, 3, Box2d{{{0, 0}}, {{32000, 32000}}}, {"superstorm_coverage", "min_height", "max_height"});
    for (int y = 0; y < 32; ++y)
        for (int x = 0; x < 32; ++x) {
            s.at(0, x, y) = (x >= 8 && x < 16 && y >= 20 && y < 28) ? 1.0f : 0.0f;
            s.at(1, x, y) = 800;
            s.at(2, x, y) = 12000;
        }
    return s;
}

bool same(const Flash& a, const Flash& b) {
    return a.time == b.time && a.position == b.position && a.intensity == b.intensity && a.ground == b.ground && a.sequence == b.sequence;
}
} // namespace

TEST(Lightning, WindowsThatTileTimeListEveryFlashOnce) {
    const Field2D set = storm_set();
    LightningOptions o;
    o.rate = 20;
    o.time = 0;
    o.window = 600;
    const auto whole = lightning_schedule(set, o);
    ASSERT_GT(whole.size(), 100u);
    std::vector<Flash> parts;
    for (double t = 0; t < 600; t += 20) {
        o.time = t;
        o.window = 20;
        const auto p = lightning_schedule(set, o);
        for (const auto& f : p) EXPECT_TRUE(f.time >= t && f.time < t + 20);
        parts.insert(parts.end(), p.begin(), p.end());
    }
    ASSERT_EQ(parts.size(), whole.size());
    for (size_t i = 0; i < whole.size(); ++i) EXPECT_TRUE(same(parts[i], whole[i])) << i;
    // Deterministic; another seed, another schedule.
    o.time = 0;
    o.window = 600;
    EXPECT_EQ(lightning_schedule(set, o).size(), whole.size());
    o.seed = 2;
    const auto other = lightning_schedule(set, o);
    EXPECT_FALSE(other.size() == whole.size() && same(other[0], whole[0]));
}

TEST(Lightning, RateSequenceShapeAndPlacement) {
    const Field2D set = storm_set();
    LightningOptions o;
    o.rate = 6; // one sequence every 10 s on average
    o.window = 36000;
    const auto flashes = lightning_schedule(set, o);
    std::map<int64_t, std::vector<Flash>> seqs;
    for (const auto& f : flashes) seqs[f.sequence].push_back(f);
    // Binomial over 36000 one-second slots with p = 0.1: 3600 +- 57 (4 sigma 228).
    EXPECT_NEAR(double(seqs.size()), 3600, 228);
    int ground_counts[3] = {0, 0, 0};
    for (const auto& [k, s] : seqs) {
        if (s.front().time < 1 || s.back().time > o.window - 3) continue; // cut by the window
        ASSERT_GE(s.size(), 4u);
        ASSERT_LE(s.size(), 5u);
        int ground = 0;
        for (size_t i = 0; i < s.size(); ++i) {
            const Flash& f = s[i];
            // In the storm's columns (texels 8..15 x 20..27), each flash near its sequence's column.
            EXPECT_GE(f.position[0], 8000);
            EXPECT_LT(f.position[0], 16000);
            EXPECT_GE(f.position[1], 20000);
            EXPECT_LT(f.position[1], 28000);
            EXPECT_LE(std::abs(f.position[0] - s.front().position[0]), 1000.0 + 1e-9);
            if (i > 0) {
                EXPECT_NEAR(f.time - s[i - 1].time, o.spacing, 1e-9);
            }
            if (i < 3) {
                // 000: several intra-cloud flashes of rising intensity, 30-60 % up the cloud.
                EXPECT_FALSE(f.ground);
                EXPECT_DOUBLE_EQ(f.intensity, o.intensity * 0.5 * double(i + 1) / 3);
                EXPECT_GE(f.position[2], 800 + 0.3 * 11200 - 1e-6);
                EXPECT_LE(f.position[2], 800 + 0.6 * 11200 + 1e-6);
            } else {
                // Then 1 to 2 ground discharges from the cloud base at full intensity.
                EXPECT_TRUE(f.ground);
                EXPECT_EQ(f.intensity, o.intensity);
                EXPECT_EQ(f.position[2], 800);
                ++ground;
            }
        }
        ++ground_counts[ground];
    }
    EXPECT_EQ(ground_counts[0], 0);
    EXPECT_GT(ground_counts[1], 1000);
    EXPECT_GT(ground_counts[2], 1000);
    // Rate 0, or no storm: no flashes; the table of none is one row with intensity 0, time -1.
    o.rate = 0;
    EXPECT_TRUE(lightning_schedule(set, o).empty());
    Field2D calm = storm_set();
    for (auto& v : calm.channel(0)) v = 0;
    o.rate = 60;
    EXPECT_TRUE(lightning_schedule(calm, o).empty());
    const Field2D empty = lightning_table({}, calm.bounds());
    EXPECT_EQ(empty.width(), 1);
    EXPECT_EQ(empty.at(empty.find_channel("time"), 0, 0), -1.0f);
    EXPECT_EQ(empty.at(empty.find_channel("intensity"), 0, 0), 0.0f);
    const Field2D t = lightning_table(flashes, set.bounds());
    EXPECT_EQ(size_t(t.width()), flashes.size());
    EXPECT_EQ(t.at(t.find_channel("ground"), 3, 0), flashes[3].ground ? 1.0f : 0.0f);
}

TEST(Lightning, ExtremeAndBadInput) {
    const Field2D set = storm_set();
    LightningOptions o;
    auto refused = [&](LightningOptions bad, const std::string& what) {
        try {
            lightning_schedule(set, bad);
            ADD_FAILURE() << what << " was accepted";
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
        }
    };
    LightningOptions b = o;
    b.rate = std::nan("");
    refused(b, "rate");
    b = o, b.rate = -1, refused(b, "rate");
    b = o, b.window = 0, refused(b, "window");
    b = o, b.time = INFINITY, refused(b, "time");
    b = o, b.spacing = 0, refused(b, "spacing");
    b = o, b.intra_flashes = 17, refused(b, "intra_flashes");
    Field2D no_heights({{2, 2}}, 1, Box2d{{{0, 0}}, {{1, 1}}}, {"coverage"});
    EXPECT_THROW(lightning_schedule(no_heights, o), Error);
    // The most a schedule can hold: 60 per minute, 16 + 4 flashes, a day.
    o.rate = 60;
    o.intra_flashes = 16;
    o.ground_max = 4;
    o.time = -1e9;
    o.window = 3600;
    const auto many = lightning_schedule(set, o);
    EXPECT_GT(many.size(), 3600u * 16);
    for (const auto& f : many) ASSERT_TRUE(std::isfinite(f.position[0]) && f.time >= o.time && f.time < o.time + o.window);
}

TEST(Lightning, TheLifecycleFlashesOnlyWhileTheStormIsMature) {
    Session s(builtin_nodes());
    s.load(std::filesystem::path(ATLAS_SOURCE_DIR) / "graphs" / "superstorm_lifecycle.yaml");
    auto flashes_at = [&](double t) {
        s.set_time(t);
        const auto v = s.get("lightning", "table", {});
        const Field2D& table = *std::get<Field2DPtr>(v);
        return table.at(table.find_channel("intensity"), 0, 0) > 0 ? table.width() : 0;
    };
    EXPECT_EQ(flashes_at(0), 0);   // forming: no lightning yet
    EXPECT_GT(flashes_at(200), 0); // mature
    EXPECT_EQ(flashes_at(440), 0); // dissipated
}

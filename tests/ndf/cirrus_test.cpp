// Cirrus texture and horizon strip: tiling, character of the three looks, fade, extremes.
#include "atlas/ndf/cirrus.h"

#include "atlas/core/error.h"
#include "atlas/core/field_math.h"
#include "atlas/ndf/generators.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>

using namespace atlas;
using namespace atlas::ndf;

namespace {
// The seam measure of tests/ndf/generators_test.cpp (seam_ratio, private to
// that file), per channel and per axis: mean |difference| across the wrap
// over the mean |difference| between neighbours inside. cell = 1: every
// interior line, since rotated streaks do not put the seam on a lattice line.
double seam_ratio_axis(const Field2D& f, int c, int axis) {
    double seam = 0, inner = 0;
    size_t ns = 0, ni = 0;
    const int W = f.width(), H = f.height();
    if (axis == 0) {
        for (int y = 0; y < H; ++y) {
            seam += std::abs(f.at(c, W - 1, y) - f.at(c, 0, y)), ++ns;
            for (int x = 1; x < W; ++x) inner += std::abs(f.at(c, x, y) - f.at(c, x - 1, y)), ++ni;
        }
    } else {
        for (int x = 0; x < W; ++x) {
            seam += std::abs(f.at(c, x, H - 1) - f.at(c, x, 0)), ++ns;
            for (int y = 1; y < H; ++y) inner += std::abs(f.at(c, x, y) - f.at(c, x, y - 1)), ++ni;
        }
    }
    return (seam / double(ns)) / (inner / double(ni));
}

// Anisotropy: mean |difference| across the streaks over mean |difference|
// along them, for streaks along x (1 = isotropic, larger = streaky).
double anisotropy(const Field2D& f, int c) {
    double along = 0, across = 0;
    for (int y = 1; y < f.height(); ++y)
        for (int x = 1; x < f.width(); ++x) {
            along += std::abs(f.at(c, x, y) - f.at(c, x - 1, y));
            across += std::abs(f.at(c, x, y) - f.at(c, x, y - 1));
        }
    return across / along;
}

// Blob statistics: connected components (4-neighbours, no wrap) of texels
// above `level` with at least 4 texels, and their mean size in texels.
struct Blobs {
    size_t count = 0;
    double mean_size = 0;
};
Blobs blobs(const Field2D& f, int c, float level) {
    const int W = f.width(), H = f.height();
    std::vector<int> label(size_t(W) * size_t(H), -1);
    std::vector<std::pair<int, int>> stack;
    Blobs b;
    size_t texels = 0;
    for (int y0 = 0; y0 < H; ++y0)
        for (int x0 = 0; x0 < W; ++x0) {
            if (f.at(c, x0, y0) <= level || label[f.index(x0, y0)] >= 0) continue;
            size_t n = 0;
            stack.assign(1, {x0, y0});
            label[f.index(x0, y0)] = 1;
            while (!stack.empty()) {
                auto [x, y] = stack.back();
                stack.pop_back();
                ++n;
                const int nx[4] = {x - 1, x + 1, x, x}, ny[4] = {y, y, y - 1, y + 1};
                for (int k = 0; k < 4; ++k)
                    if (nx[k] >= 0 && nx[k] < W && ny[k] >= 0 && ny[k] < H && f.at(c, nx[k], ny[k]) > level &&
                        label[f.index(nx[k], ny[k])] < 0) {
                        label[f.index(nx[k], ny[k])] = 1;
                        stack.push_back({nx[k], ny[k]});
                    }
            }
            if (n >= 4) ++b.count, texels += n;
        }
    b.mean_size = b.count ? double(texels) / double(b.count) : 0;
    return b;
}

double covered(const Field2D& f, int c, float level) {
    size_t n = 0;
    for (float v : f.channel(c)) n += v > level;
    return double(n) / double(f.voxel_count());
}
} // namespace

TEST(Cirrus, TextureTilesWithoutSeamInEveryChannel) {
    for (Vec2i dir : {Vec2i{{1, 0}}, Vec2i{{2, 1}}, Vec2i{{-1, 3}}}) {
        CirrusSpec s;
        s.resolution = {{256, 256}};
        s.streak_direction = dir;
        s.seed = 5;
        const Field2D t = cirrus_texture(s, nullptr);
        ASSERT_EQ(t.channel_names(), cirrus_channels());
        for (int c = 0; c < 3; ++c)
            for (int axis = 0; axis < 2; ++axis) {
                const double r = seam_ratio_axis(t, c, axis);
                // Below 1 is no seam: where the wrap falls on a lattice line of
                // an unrotated octave, the quintic fade is flat there.
                EXPECT_LT(r, 1.6) << "channel " << c << " axis " << axis << " dir " << dir[0] << "," << dir[1];
                EXPECT_GT(r, 0.3) << "channel " << c << " axis " << axis;
            }
        for (int c = 0; c < 3; ++c) {
            const auto st = channel_stats(t.channel(c));
            EXPECT_GE(st.min, 0.0);
            EXPECT_LE(st.max, 1.0);
            EXPECT_GT(st.max - st.min, 0.5) << c;
        }
    }
    // The measure can fail: a non-tiling map shows a seam.
    const Field2D g = gradient_linear({{256, 256}}, Box2d{{{0, 0}}, {{1, 1}}}, {{0, 0}}, {{1, 0}}, nullptr);
    EXPECT_GT(seam_ratio_axis(g, 0, 0), 10.0);
}

TEST(Cirrus, ThreeLooksDifferInCharacter) {
    CirrusSpec s;
    s.resolution = {{256, 256}};
    s.streak_direction = {{1, 0}};
    s.seed = 11;
    const Field2D t = cirrus_texture(s, nullptr);
    const double a_stratus = anisotropy(t, 0), a_cirrus = anisotropy(t, 1), a_cumulus = anisotropy(t, 2);
    const Blobs b_stratus = blobs(t, 0, 0.3f), b_cirrus = blobs(t, 1, 0.3f), b_cumulus = blobs(t, 2, 0.3f);
    std::printf("blobs %zu %zu %zu  mean size %.1f %.1f %.1f\n", b_stratus.count, b_cirrus.count, b_cumulus.count, b_stratus.mean_size,
                b_cirrus.mean_size, b_cumulus.mean_size);
    const double c_stratus = covered(t, 0, 0.1f), c_cirrus = covered(t, 1, 0.1f), c_cumulus = covered(t, 2, 0.1f);
    RecordProperty("anisotropy", std::to_string(a_stratus) + " " + std::to_string(a_cirrus) + " " + std::to_string(a_cumulus));
    RecordProperty("covered", std::to_string(c_stratus) + " " + std::to_string(c_cirrus) + " " + std::to_string(c_cumulus));
    std::printf("anisotropy %.3f %.3f %.3f  covered %.3f %.3f %.3f\n", a_stratus, a_cirrus, a_cumulus, c_stratus, c_cirrus, c_cumulus);
    // Streaks: the two cirrus looks are anisotropic along the streak direction, the puffs are not.
    EXPECT_GT(a_stratus, 2.0);
    EXPECT_GT(a_cirrus, 2.0);
    EXPECT_GT(a_cumulus, 0.8);
    EXPECT_LT(a_cumulus, 1.25);
    // Puffs: many separate blobs.
    EXPECT_GT(b_cumulus.count, 3 * b_stratus.count);
    EXPECT_GT(b_cumulus.count, 2 * b_cirrus.count);
    EXPECT_LT(b_cumulus.mean_size * 20, b_stratus.mean_size); // small puffs against one wide veil
    // The veil covers most of the sky, the fibres less.
    EXPECT_GT(c_stratus, c_cirrus + 0.1);
    // Turning the streak direction turns the anisotropy.
    s.streak_direction = {{0, 1}};
    const Field2D r = cirrus_texture(s, nullptr);
    EXPECT_LT(anisotropy(r, 1), 0.5);
}

TEST(Cirrus, HorizonStripTilesAlongItsLengthAndFadesUp) {
    CirrusHorizonSpec s;
    s.seed = 2;
    const Field2D h = cirrus_horizon(s, nullptr);
    ASSERT_EQ(h.resolution(), (Vec2i{{2048, 128}}));
    const double r = seam_ratio_axis(h, 0, 0);
    EXPECT_LT(r, 1.6);
    EXPECT_GT(r, 0.6);
    // Not tileable upward (it fades): the measure sees that.
    EXPECT_GT(seam_ratio_axis(h, 0, 1), 3.0);
    // Rows: never above the fade envelope, 0 at the top, denser low.
    double low = 0, high = 0;
    for (int y = 0; y < 128; ++y) {
        const double v = (y + 0.5) / 128;
        const double u = std::clamp((v - s.fade_start) / (1 - s.fade_start), 0.0, 1.0);
        const double envelope = 1 - u * u * (3 - 2 * u);
        double row = 0;
        for (int x = 0; x < 2048; ++x) {
            ASSERT_LE(h.at(0, x, y), envelope + 1e-6) << y;
            ASSERT_GE(h.at(0, x, y), 0.0f);
            row += h.at(0, x, y);
        }
        (y < 32 ? low : y >= 96 ? high : row) += row;
    }
    EXPECT_GT(low, 3 * high);
    EXPECT_GT(low / (32 * 2048), 0.1); // there are clouds at the horizon
}

TEST(Cirrus, ExtremesAndDeterminism) {
    CirrusSpec s;
    s.resolution = {{1, 1}};
    Field2D one = cirrus_texture(s, nullptr);
    for (int c = 0; c < 3; ++c) EXPECT_TRUE(std::isfinite(one.at(c, 0, 0)));
    s.resolution = {{64, 32}};
    s.stretch = 64;
    s.period = 256;
    s.warp = 1;
    const Field2D extreme = cirrus_texture(s, nullptr);
    for (int c = 0; c < 3; ++c)
        for (float v : extreme.channel(c)) ASSERT_TRUE(std::isfinite(v) && v >= 0 && v <= 1);
    auto expect_error = [](auto fn, const char* param) {
        try {
            fn();
            ADD_FAILURE() << "no error for " << param;
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find(param), std::string::npos) << e.what();
        }
    };
    CirrusSpec bad;
    bad.streak_direction = {{0, 0}};
    expect_error([&] { cirrus_texture(bad, nullptr); }, "streak_direction");
    bad = CirrusSpec{};
    bad.warp = NAN;
    expect_error([&] { cirrus_texture(bad, nullptr); }, "warp");
    bad = CirrusSpec{};
    bad.resolution = {{0, 4}};
    expect_error([&] { cirrus_texture(bad, nullptr); }, "resolution");
    CirrusHorizonSpec hb;
    hb.fade_start = 1;
    expect_error([&] { cirrus_horizon(hb, nullptr); }, "fade_start");
    hb = CirrusHorizonSpec{};
    hb.cells_up = 0;
    expect_error([&] { cirrus_horizon(hb, nullptr); }, "cells_up");
    // Bounds place the tile in the world; the texels do not depend on them.
    CirrusSpec placed;
    placed.resolution = {{32, 32}};
    placed.bounds = Box2d{{{0, 0}}, {{60000, 60000}}};
    const Field2D world = cirrus_texture(placed, nullptr);
    EXPECT_EQ(world.bounds(), placed.bounds);
    placed.bounds = Box2d{{{0, 0}}, {{1, 1}}};
    const Field2D unit = cirrus_texture(placed, nullptr);
    for (int c = 0; c < 3; ++c)
        for (size_t i = 0; i < unit.voxel_count(); ++i) ASSERT_EQ(world.channel(c)[i], unit.channel(c)[i]);
    placed.bounds = Box2d{{{5, 0}}, {{1, 1}}};
    expect_error([&] { cirrus_texture(placed, nullptr); }, "bounds");
    // Same bytes on one thread and many.
    CirrusSpec d;
    d.resolution = {{128, 96}};
    d.streak_direction = {{3, -2}};
    CirrusHorizonSpec dh;
    dh.resolution = {{512, 32}};
    const Field2D many = cirrus_texture(d, nullptr), hmany = cirrus_horizon(dh, nullptr);
    tbb::global_control one_thread(tbb::global_control::max_allowed_parallelism, 1);
    EXPECT_TRUE(many == cirrus_texture(d, nullptr));
    EXPECT_TRUE(hmany == cirrus_horizon(dh, nullptr));
}

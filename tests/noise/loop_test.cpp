// A noise that loops in time (atlas/noise/loop.h, the noise nodes' loop_shift
// and loop_phase): phase 0 and phase 1 are the unlooped field byte for byte,
// phases close to either end are close to it (no jump where the loop wraps),
// the middle differs and keeps the field's contrast, and the tiling in space
// survives; bad phases are refused.
#include "atlas/core/error.h"
#include "atlas/graph/evaluator.h"
#include "atlas/graph/node.h"
#include "atlas/noise/loop.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

using namespace atlas;

namespace {
std::vector<float> cook_at(Session& s, double phase) {
    s.set("n", "loop_phase", phase);
    const auto f = std::get<Field3DPtr>(s.get("n", "out"));
    const auto c = f->channel(0);
    return {c.begin(), c.end()};
}
double rms_diff(const std::vector<float>& a, const std::vector<float>& b) {
    double s = 0;
    for (size_t i = 0; i < a.size(); ++i) s += (double(a[i]) - b[i]) * (double(a[i]) - b[i]);
    return std::sqrt(s / double(a.size()));
}
double stddev(const std::vector<float>& a) {
    double m = 0, s = 0;
    for (float v : a) m += v;
    m /= double(a.size());
    for (float v : a) s += (v - m) * (v - m);
    return std::sqrt(s / double(a.size()));
}
} // namespace

TEST(NoiseLoop, WrapsSeamlesslyAndKeepsContrast) {
    const std::string graph = "atlas: 1\nnodes:\n  n: {type: noise/perlin_worley, params: {resolution: [24, 24, 8], "
                              "bounds_max: [24, 24, 8], period: [4, 4, 4], octaves: 3, seed: 5, loop_shift: [1.5, 0.5, 0]}}\n"
                              "  plain: {type: noise/perlin_worley, params: {resolution: [24, 24, 8], bounds_max: [24, 24, 8], "
                              "period: [4, 4, 4], octaves: 3, seed: 5}}\n"
                              "outputs:\n  - {node: n, file: n.exr}\n  - {node: plain, file: plain.exr}\n";
    Session s(builtin_nodes());
    s.load_text(graph, "loop.yaml", ".");
    const auto plain = std::get<Field3DPtr>(s.get("plain", "out"));
    const std::vector<float> ref(plain->channel(0).begin(), plain->channel(0).end());
    EXPECT_EQ(cook_at(s, 0.0), ref);
    EXPECT_EQ(cook_at(s, 1.0), ref);
    const double sd = stddev(ref);
    ASSERT_GT(sd, 0.02); // real noise
    const double near0 = rms_diff(cook_at(s, 0.02), ref), near1 = rms_diff(cook_at(s, 0.98), ref);
    const std::vector<float> mid = cook_at(s, 0.5);
    const double far = rms_diff(mid, ref);
    EXPECT_LT(near0, 0.15 * far) << near0 << " " << far;
    EXPECT_LT(near1, 0.15 * far) << near1 << " " << far;
    EXPECT_GT(far, 0.5 * sd);
    EXPECT_NEAR(stddev(mid), sd, 0.15 * sd); // the crossfade keeps the contrast (a plain one: 0.71)
    // Still tiles in space: the 24-voxel field repeats every 24 voxels, so its opposite
    // faces continue each other as in the unlooped field (x = 0 beside x = 23).
    double edge = 0, inner = 0;
    for (int z = 0; z < 8; ++z)
        for (int y = 0; y < 24; ++y) {
            const size_t row = size_t(z) * 576 + size_t(y) * 24;
            edge += std::abs(mid[row] - mid[row + 23]);
            inner += std::abs(mid[row + 11] - mid[row + 12]);
        }
    EXPECT_LT(edge, 1.6 * inner) << "the wrap seam differs from a step inside";
    EXPECT_THROW(s.set("n", "loop_phase", 1.5), Error); // refused at the parameter, by its range
}

TEST(NoiseLoop, CrossfadeRefusesMismatchedFieldsAndPhases) {
    std::vector<float> a{0.f, 1.f}, b{1.f, 0.f}, c{1.f};
    EXPECT_THROW(noise::loop_crossfade(a, c, 0.5), Error);
    EXPECT_THROW(noise::loop_crossfade(a, b, -0.1), Error);
    EXPECT_THROW(noise::loop_crossfade(a, b, std::nan("")), Error);
    noise::loop_crossfade(a, b, 0.5); // mean 0.5, the blend 0.5 everywhere: nothing to rescale
    EXPECT_FLOAT_EQ(a[0], 0.5f);
    EXPECT_FLOAT_EQ(a[1], 0.5f);
}

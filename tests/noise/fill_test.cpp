// fill_noise: determinism across thread counts, seeds, extremes, validation,
// and the production recipes at small sizes.
#include "noise_test_util.h"

#include "atlas/core/error.h"
#include "atlas/noise/recipes.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <cstring>

namespace atlas::noise {
namespace {

Field3D filled(const NoiseSpec& s, int threads, Vec3i res = {{20, 12, 9}}) {
    Field3D f(res, noise_components(s.kernel, 3), Box3d{{{0, 0, 0}}, {{1, 1, 1}}});
    tbb::task_arena arena(threads);
    arena.execute([&] { fill_noise(f, 0, s); });
    return f;
}

bool same_bytes(const Field3D& a, const Field3D& b) {
    if (a.channels() != b.channels()) return false;
    for (int c = 0; c < a.channels(); ++c)
        if (std::memcmp(a.channel(c).data(), b.channel(c).data(), a.channel(c).size_bytes()) != 0) return false;
    return true;
}

TEST(NoiseFill, SameBytesForOneAndTwoThreadsAndSameSeed) {
    for (const auto& [name, base] : test::all_kernels()) {
        NoiseSpec s = base;
        s.fractal.octaves = 2;
        s.output.normalize = s.kernel != Kernel::Curl;
        const Field3D one = filled(s, 1), two = filled(s, 2), again = filled(s, 2);
        EXPECT_TRUE(same_bytes(one, two)) << name;
        EXPECT_TRUE(same_bytes(two, again)) << name;
    }
}

TEST(NoiseFill, DifferentSeedsDiffer) {
    for (const auto& [name, base] : test::all_kernels()) {
        NoiseSpec s = base;
        const Field3D a = filled(s, 2);
        s.seed += 1;
        const Field3D b = filled(s, 2);
        EXPECT_FALSE(same_bytes(a, b)) << name;
    }
}

TEST(NoiseFill, TwoDimensionalFillIsDeterministicAndWithinRange) {
    for (const auto& [name, kernel_settings] : test::all_kernels()) {
        // A lambda captures a copy's name, not a structured binding (clang 14 cannot).
        const NoiseSpec& s = kernel_settings;
        const int comps = noise_components(s.kernel, 2);
        Field2D a({{33, 17}}, comps, Box2d{{{0, 0}}, {{1, 1}}}), b({{33, 17}}, comps, Box2d{{{0, 0}}, {{1, 1}}});
        tbb::task_arena(1).execute([&] { fill_noise(a, 0, s); });
        tbb::task_arena(2).execute([&] { fill_noise(b, 0, s); });
        EXPECT_TRUE(a == b) << name;
        const ValueRange r = noise_output_range(s, 2);
        for (int c = 0; c < comps; ++c)
            for (float v : a.channel(c)) {
                ASSERT_TRUE(std::isfinite(v)) << name;
                ASSERT_GE(v, r.lo) << name;
                ASSERT_LE(v, r.hi) << name;
            }
    }
}

// Far from the origin: finite, in range, and still tiling (the coordinate is
// reduced modulo the period in double before anything is rounded to float).
TEST(NoiseFill, MillionCellOffsetStaysFiniteAndClose) {
    for (const auto& [name, base] : test::all_kernels()) {
        NoiseSpec near = base, far = base;
        // 1e6 cells away but a whole number of tiles: same signal expected.
        for (int a = 0; a < 3; ++a) far.offset[a] = double(base.period[a]) * std::round(1e6 / base.period[a]);
        const Field3D fa = filled(near, 2), fb = filled(far, 2);
        double worst = 0;
        for (int c = 0; c < fa.channels(); ++c)
            for (size_t i = 0; i < fa.voxel_count(); ++i) {
                ASSERT_TRUE(std::isfinite(fb.channel(c)[i])) << name;
                worst = std::max(worst, double(std::fabs(fa.channel(c)[i] - fb.channel(c)[i])));
            }
        EXPECT_LE(worst, 1e-4) << name; // docs/noise.md: about 1e-10 cells of position error
        // Non-integer offset near 1e6: finite and in range.
        NoiseSpec odd = base;
        odd.offset = {{1e6 + 0.3, -1e6 - 0.7, 1e6 + 0.1}};
        const Field3D fo = filled(odd, 2);
        const ValueRange r = noise_output_range(odd, 3);
        for (int c = 0; c < fo.channels(); ++c)
            for (float v : fo.channel(c)) {
                ASSERT_TRUE(std::isfinite(v)) << name;
                ASSERT_GE(v, r.lo) << name;
                ASSERT_LE(v, r.hi) << name;
            }
    }
}

void expect_error_naming(const NoiseSpec& s, const std::string& param) {
    try {
        s.validate(3);
        Field3D f({{2, 2, 2}}, 3, Box3d{{{0, 0, 0}}, {{1, 1, 1}}});
        fill_noise(f, 0, s);
        ADD_FAILURE() << "no error for " << param;
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find(param), std::string::npos) << e.what();
    }
}

TEST(NoiseFill, InvalidParametersThrowNamingTheParameter) {
    NoiseSpec s = test::make(Kernel::Gradient);
    NoiseSpec t = s;
    t.fractal.octaves = 0;
    expect_error_naming(t, "fractal.octaves");
    t = s;
    t.fractal.octaves = 17;
    expect_error_naming(t, "fractal.octaves");
    t = s;
    t.fractal.lacunarity = 1000; // 5 * 1000^3 cells > 2^30
    t.fractal.octaves = 4;
    expect_error_naming(t, "lacunarity");
    t = s;
    t.period[1] = 0;
    expect_error_naming(t, "period.y");
    t = s;
    t.frequency = -1;
    expect_error_naming(t, "frequency");
    t = s;
    t.frequency = std::nan("");
    expect_error_naming(t, "frequency");
    t = s;
    t.offset[2] = HUGE_VAL;
    expect_error_naming(t, "offset.z");
    t = s;
    t.fractal.gain = std::nan("");
    expect_error_naming(t, "fractal.gain");
    t = s;
    t.worley.jitter = 2;
    expect_error_naming(t, "worley.jitter");
    t = s;
    t.output.remap = true;
    t.output.in_min = t.output.in_max = 0.5;
    expect_error_naming(t, "output.in_max");
    t = s;
    t.kernel = Kernel::Curl;
    t.fractal.combinator = Combinator::Ridged;
    expect_error_naming(t, "combinator");
    // Too few channels for the curl's three components.
    NoiseSpec c = test::make(Kernel::Curl);
    Field3D f({{2, 2, 2}}, 2, Box3d{{{0, 0, 0}}, {{1, 1, 1}}});
    EXPECT_THROW(fill_noise(f, 0, c), Error);
    EXPECT_THROW(sample_noise(c, std::span<const Vec3d>(std::vector<Vec3d>{{{std::nan(""), 0, 0}}})), Error);
}

// Degenerate but valid: defined, finite results (and no hang).
TEST(NoiseFill, DegenerateParametersGiveDefinedResults) {
    for (const auto& [name, base] : test::all_kernels()) {
        NoiseSpec s = base;
        s.frequency = 0; // every voxel at the same lattice point: constant
        Field3D f = filled(s, 2, {{5, 4, 3}});
        for (int c = 0; c < f.channels(); ++c)
            for (float v : f.channel(c)) {
                ASSERT_TRUE(std::isfinite(v)) << name;
                EXPECT_EQ(v, f.channel(c)[0]) << name;
            }
        NoiseSpec p1 = base; // period 1: one cell per tile
        p1.period = {{1, 1, 1}};
        NoiseSpec o16 = base; // 16 octaves, lacunarity 2: lattice up to 4 * 2^15 cells
        o16.fractal.octaves = 16;
        NoiseSpec lac = base; // huge lacunarity that still fits
        lac.fractal.octaves = 2;
        lac.fractal.lacunarity = 1024;
        NoiseSpec g0 = base; // gain 0: only octave 0 counts
        g0.fractal.octaves = 5;
        g0.fractal.gain = 0;
        for (const NoiseSpec& x : {p1, o16, lac, g0}) {
            const Field3D g = filled(x, 2, {{6, 5, 4}});
            const ValueRange r = noise_output_range(x, 3);
            for (int c = 0; c < g.channels(); ++c)
                for (float v : g.channel(c)) {
                    ASSERT_TRUE(std::isfinite(v)) << name;
                    ASSERT_GE(v, r.lo) << name;
                    ASSERT_LE(v, r.hi) << name;
                }
        }
        // gain 0 equals the single-octave signal.
        NoiseSpec one = base;
        EXPECT_TRUE(same_bytes(filled(g0, 2, {{6, 5, 4}}), filled(one, 2, {{6, 5, 4}}))) << name;
    }
}

TEST(NoiseFill, NormalizeUsesTheFullRange) {
    NoiseSpec s = test::make(Kernel::Alligator);
    s.output.normalize = true;
    const Field3D f = filled(s, 2);
    const auto [mn, mx] = std::minmax_element(f.channel(0).begin(), f.channel(0).end());
    EXPECT_EQ(*mn, 0.0f);
    EXPECT_EQ(*mx, 1.0f);
}

TEST(NoiseFill, TwiceFoldedMatchesTheNubisFormula) {
    NoiseSpec s = test::make(Kernel::Value);
    NoiseSpec folded = s;
    folded.output.fold_count = 2;
    const Field3D a = filled(s, 2), b = filled(folded, 2);
    for (size_t i = 0; i < a.voxel_count(); ++i) {
        const float n = a.channel(0)[i];
        EXPECT_NEAR(b.channel(0)[i], std::fabs(std::fabs(n * 2 - 1) * 2 - 1), 1e-6);
    }
}

TEST(NoiseFill, CancellationStopsTheFill) {
    ProgressSink p;
    p.is_cancelled = [] { return true; };
    Field3D f({{8, 8, 8}}, 1, Box3d{{{0, 0, 0}}, {{1, 1, 1}}});
    EXPECT_THROW(fill_noise(f, 0, test::make(Kernel::Gradient), &p), CancelledError);
}

TEST(NoiseRecipes, SmallNubisAndHzdSetsAreDeterministicTileableAndInRange) {
    const Field3D a = make_nubis_noise(12, 3);
    Field3D b = a;
    tbb::task_arena(1).execute([&] { b = make_nubis_noise(12, 3); });
    EXPECT_TRUE(same_bytes(a, b));
    ASSERT_EQ(a.channels(), 4);
    for (int c = 0; c < 4; ++c) {
        const auto [mn, mx] = std::minmax_element(a.channel(c).begin(), a.channel(c).end());
        EXPECT_EQ(*mn, 0.0f) << c;
        EXPECT_EQ(*mx, 1.0f) << c;
    }
    const HzdNoise h = make_hzd_noise(10, 6, 9, 4);
    EXPECT_EQ(h.low.channels(), 4);
    EXPECT_EQ(h.high.channels(), 3);
    EXPECT_EQ(h.curl.channels(), 2);
    for (const Field3D* f : {&h.low, &h.high})
        for (int c = 0; c < f->channels(); ++c)
            for (float v : f->channel(c)) ASSERT_TRUE(v >= 0 && v <= 1);
    for (int c = 0; c < 2; ++c)
        for (float v : h.curl.channel(c)) ASSERT_TRUE(v >= 0 && v <= 1);
    EXPECT_THROW(make_nubis_noise(0, 1), Error);
}

} // namespace
} // namespace atlas::noise

// The SIMD paths of the noise kernels write the same bytes as the scalar
// path (docs/noise.md, "SIMD"): every path this machine supports against the
// scalar one, on fields (tabulated lattices, rows of any length) and on point
// lookups (hashed lattices) at huge and tiny coordinates; a few million
// samples per path.
#include "noise_test_util.h"
#include "../../libatlas/src/noise/lattice.h"

#include "atlas/core/error.h"
#include "atlas/noise/recipes.h"
#include "atlas/noise/simd.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <random>

namespace atlas::noise {
namespace {

// Restores automatic dispatch when a test ends.
struct PathGuard {
    ~PathGuard() { set_simd_path(SimdPath::Auto); }
};

std::vector<float> field_bytes(const NoiseSpec& s, Vec3i res) {
    Field3D f(res, noise_components(s.kernel, 3), Box3d{{{0, 0, 0}}, {{1, 1, 1}}});
    fill_noise(f, 0, s);
    std::vector<float> r;
    for (int c = 0; c < f.channels(); ++c) r.insert(r.end(), f.channel(c).begin(), f.channel(c).end());
    return r;
}

// First differing index, or -1.
int64_t first_difference(const std::vector<float>& a, const std::vector<float>& b) {
    if (a.size() != b.size()) return 0;
    for (size_t i = 0; i < a.size(); ++i)
        if (std::memcmp(&a[i], &b[i], sizeof(float)) != 0) return int64_t(i);
    return -1;
}

// The kernels with SIMD paths (alone and inside the composite kernels), with
// several octaves so higher-frequency lattices (and their hashed, untabulated
// form for large periods) are covered.
std::vector<test::NamedSpec> simd_specs() {
    std::vector<test::NamedSpec> r;
    for (auto& ns : test::all_kernels()) {
        const Kernel k = ns.spec.kernel;
        if (k == Kernel::Value || k == Kernel::Curl) continue;
        r.push_back(ns);
        test::NamedSpec f = ns;
        f.name += "+fbm3";
        f.spec.fractal.octaves = 3;
        f.spec.period = {{5, 8, 3}};
        f.spec.offset = {{0.37, 11.2, 1e5}};
        f.spec.frequency = 3;
        r.push_back(f);
    }
    test::NamedSpec j{"worley-jitter0.3", test::make(Kernel::Worley)};
    j.spec.worley.jitter = 0.3;
    r.push_back(j);
    test::NamedSpec big{"gradient-hashed-lattice", test::make(Kernel::Gradient, 160)}; // 160*161*162 points: hashed
    r.push_back(big);
    test::NamedSpec bigw{"worley-hashed-lattice", test::make(Kernel::Worley, 160)};
    r.push_back(bigw);
    return r;
}

TEST(NoiseSimd, PathsAreListedAndForcedPathsAreUsedByName) {
    PathGuard guard;
    const auto paths = supported_simd_paths();
    ASSERT_FALSE(paths.empty());
    EXPECT_EQ(paths.front(), SimdPath::Scalar);
    for (SimdPath p : paths) {
        set_simd_path(p);
        EXPECT_EQ(simd_path(), p);
        EXPECT_EQ(parse_simd_path(simd_path_name(p)), p);
    }
    EXPECT_THROW(parse_simd_path("avx9"), Error);
#if defined(__x86_64__)
    EXPECT_NE(std::find(paths.begin(), paths.end(), SimdPath::Sse2), paths.end()); // the x86-64 baseline
#endif
}

TEST(NoiseSimd, FieldsHaveTheSameBytesOnEveryPath) {
    PathGuard guard;
    const auto paths = supported_simd_paths();
    // Rows of 1, 3, 13 and 67 texels: whole and partial SIMD batches.
    const Vec3i sizes[] = {{{67, 23, 17}}, {{13, 5, 7}}, {{1, 4, 3}}, {{3, 2, 2}}};
    size_t samples = 0;
    for (const auto& [name, s] : simd_specs())
        for (const Vec3i& res : sizes) {
            set_simd_path(SimdPath::Scalar);
            const std::vector<float> ref = field_bytes(s, res);
            float lo = ref.empty() ? 0 : ref[0], hi = lo;
            for (float v : ref) lo = std::min(lo, v), hi = std::max(hi, v);
            if (res[0] * res[1] * res[2] > 1000) {
                EXPECT_LT(lo, hi) << name << ": a constant field tests nothing"; // the reference is real noise
            }
            for (SimdPath p : paths) {
                set_simd_path(p);
                const std::vector<float> got = field_bytes(s, res);
                const int64_t d = first_difference(ref, got);
                EXPECT_EQ(d, -1) << name << " " << res[0] << "x" << res[1] << "x" << res[2] << " path " << simd_path_name(p) << ": value "
                                 << (d >= 0 && size_t(d) < got.size() ? got[size_t(d)] : 0.f) << " vs scalar "
                                 << (d >= 0 && size_t(d) < ref.size() ? ref[size_t(d)] : 0.f);
                samples += got.size();
            }
        }
    EXPECT_GT(samples, size_t(1) << 20);
}

TEST(NoiseSimd, PointLookupsAtHugeAndTinyCoordinatesHaveTheSameBytesOnEveryPath) {
    PathGuard guard;
    std::mt19937_64 rng(21);
    std::vector<Vec3d> pts;
    const double scales[] = {1e-30, 1e-9, 1e-3, 1.0, 37.5, 1e6, 1e9, 1e12};
    for (double sc : scales)
        for (int i = 0; i < 4000; ++i) {
            Vec3d p;
            for (int a = 0; a < 3; ++a) p[a] = std::uniform_real_distribution<double>(-1, 1)(rng) * sc;
            pts.push_back(p);
        }
    // Lattice corners and exact integers, where a fraction is 0 or rounds to 1.
    for (int i = 0; i < 4000; ++i) pts.push_back({{double(i % 17) / 3, double(i / 17) / 5, -double(i % 7)}});
    pts.push_back({{1.0 - 1e-17, 0.5, 2.0 - 1e-16}});
    for (const auto& [name, s] : simd_specs()) {
        set_simd_path(SimdPath::Scalar);
        const std::vector<float> ref = sample_noise(s, std::span<const Vec3d>(pts));
        for (SimdPath p : supported_simd_paths()) {
            set_simd_path(p);
            const std::vector<float> got = sample_noise(s, std::span<const Vec3d>(pts));
            const int64_t d = first_difference(ref, got);
            EXPECT_EQ(d, -1) << name << " path " << simd_path_name(p) << " point "
                             << (d >= 0 ? d / int64_t(noise_components(s.kernel, 3)) : -1);
        }
    }
}

TEST(NoiseSimd, RecipesHaveTheSameBytesOnEveryPath) {
    PathGuard guard;
    set_simd_path(SimdPath::Scalar);
    const auto ref = make_nubis_noise(16, 3);
    for (SimdPath p : supported_simd_paths()) {
        set_simd_path(p);
        const auto got = make_nubis_noise(16, 3);
        ASSERT_EQ(got.channels(), ref.channels());
        for (int c = 0; c < ref.channels(); ++c)
            EXPECT_EQ(std::memcmp(got.channel(c).data(), ref.channel(c).data(), ref.channel(c).size_bytes()), 0)
                << "channel " << c << " path " << simd_path_name(p);
    }
}

} // namespace
} // namespace atlas::noise

// The hashed lattices' corners (corner_bits3, shared by the scalar cell cache and
// every SIMD path) against lattice_bits itself, corner by corner: the chain
// shared between corners must give hash_coords' bits, also at negative and
// huge coordinates; first_i = 1 leaves the x0 face as the caller had it.
TEST(NoiseLattice, SharedHashChainGivesEachCornersOwnBits) {
    using namespace atlas::noise::detail;
    const int coords[] = {0, 1, 7, 127, 128, 255, -1, -129, 1 << 20, 2147483647, -2147483647 - 1};
    size_t checked = 0;
    for (uint32_t seed : {0u, 1u, 0xDEADBEEFu})
        for (uint32_t stream : {0u, 3u})
            for (int a : coords)
                for (int b : coords) {
                    const int xs[2] = {a, b}, ys[2] = {b, a ^ 5}, zs[2] = {a / 3, b / 2};
                    int out[8];
                    corner_bits3(seed, stream, xs, ys, zs, 15u, 0, out);
                    for (int k = 0; k < 8; ++k) {
                        const uint64_t want = lattice_bits(seed, stream, xs[k & 1], ys[(k >> 1) & 1], zs[k >> 2]) & 15u;
                        ASSERT_EQ(uint64_t(out[k]), want) << seed << " " << a << " " << b << " corner " << k;
                        ++checked;
                    }
                    int kept[8] = {-1, -1, -1, -1, -1, -1, -1, -1};
                    corner_bits3(seed, stream, xs, ys, zs, 15u, 1, kept);
                    for (int k = 0; k < 8; ++k) EXPECT_EQ(kept[k], k % 2 == 0 ? -1 : out[k]) << k;
                }
    EXPECT_EQ(checked, size_t(3 * 2 * 11 * 11 * 8));
}

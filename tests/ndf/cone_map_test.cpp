// Cone-step maps: pyramid == brute force; marching never passes the surface.
#include "atlas/ndf/cone_map.h"
#include "atlas/ndf/distance_map.h"

#include "atlas/core/error.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

using namespace atlas;
using namespace atlas::ndf;

namespace {
Field2D random_heights(int w, int h, uint32_t seed, double max_height, bool smooth) {
    Field2D f({{w, h}}, 1, {{{0, 0}}, {{double(w), double(h)}}}, {"h"});
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0, 1);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            double v = u(rng) * max_height;
            if (smooth) v = max_height * (0.5 + 0.25 * std::sin(x * 0.7 + seed) * std::cos(y * 0.5) + 0.25 * u(rng));
            f.at(0, x, y) = float(v);
        }
    return f;
}

// Box-column heightfield (texel units): the first parameter along the ray
// where it is inside a solid column, brute force over all columns.
double first_hit(const Field2D& h, double px, double py, double pz, double dx, double dy, double dz) {
    double best = INFINITY;
    for (int y = 0; y < h.height(); ++y)
        for (int x = 0; x < h.width(); ++x) {
            double t0 = 0, t1 = INFINITY;
            auto slab = [&](double p, double d, double lo, double hi) {
                if (d == 0) {
                    if (p < lo || p > hi) t1 = -1;
                    return;
                }
                double a = (lo - p) / d, b = (hi - p) / d;
                if (a > b) std::swap(a, b);
                t0 = std::max(t0, a);
                t1 = std::min(t1, b);
            };
            slab(px, dx, x, x + 1.0);
            slab(py, dy, y, y + 1.0);
            if (!(t0 <= t1)) continue;
            // z falls along the ray; inside the column below its top from t_top on.
            const double top = h.at(0, x, y);
            const double t_top = (top - pz) / dz; // dz < 0
            const double t = std::max(t0, t_top);
            if (t <= t1) best = std::min(best, t);
        }
    return best;
}

// Marches with the cone map; returns the largest parameter reached. With
// `bilinear`, apex and ratio are filtered bilinearly (robust map).
double march(const Field2D& cones, const Field2D& h, bool bilinear, double px, double py, double pz, double dx, double dy, double dz,
             int& steps) {
    double t = 0;
    steps = 0;
    for (int i = 0; i < 2000; ++i) {
        const double x = px + t * dx, y = py + t * dy, z = pz + t * dz;
        if (x < 0 || y < 0 || x >= h.width() || y >= h.height()) break;
        double apex, ratio;
        if (bilinear) {
            apex = cones.sample_texel(0, x, y, WrapMode::Clamp);
            ratio = cones.sample_texel(1, x, y, WrapMode::Clamp);
        } else {
            const int ix = int(x), iy = int(y);
            apex = h.at(0, ix, iy);
            ratio = cones.at(0, ix, iy);
        }
        const double s = cone_step_length(ratio, z, apex, dz);
        if (s < 1e-6) break;
        t += s;
        ++steps;
    }
    return t;
}
} // namespace

TEST(ConeMap, PyramidEqualsBruteForce) {
    for (uint32_t seed = 0; seed < 6; ++seed)
        for (bool robust : {false, true}) {
            const int w = 8 + int(seed) * 3, hh = 5 + int(seed) * 4;
            Field2D h = random_heights(w, hh, seed, seed % 2 ? 3.0 : 20.0, seed % 3 == 0);
            ConeMapOptions opt;
            opt.robust = robust;
            opt.texel_size = seed % 2 ? 1.0 : 2.5;
            Field2D a = cone_map(h, 0, opt, nullptr);
            Field2D b = cone_map_brute_force(h, 0, opt, nullptr);
            ASSERT_TRUE(a == b) << "seed " << seed << " robust " << robust;
        }
}

TEST(ConeMap, FlatAndDegenerate) {
    Field2D flat({{4, 4}}, 1, {{{0, 0}}, {{4, 4}}});
    ConeMapOptions opt;
    Field2D c = cone_map(flat, 0, opt, nullptr);
    for (float v : c.channel(0)) EXPECT_EQ(v, float(opt.max_ratio));
    Field2D one({{1, 1}}, 1, {{{0, 0}}, {{1, 1}}});
    EXPECT_NO_THROW(cone_map(one, 0, opt, nullptr));
    flat.at(0, 1, 1) = NAN;
    EXPECT_THROW(cone_map(flat, 0, opt, nullptr), Error);
    opt.texel_size = 0;
    EXPECT_THROW(cone_map(one, 0, opt, nullptr), Error);
}

TEST(ConeMap, MarchingNeverPassesTheSurface) {
    std::mt19937 rng(42);
    std::uniform_real_distribution<double> u(0, 1);
    for (uint32_t seed = 0; seed < 8; ++seed) {
        const int n = 12 + int(seed);
        Field2D h = random_heights(n, n, seed + 100, 6.0, seed % 2 == 0);
        for (bool robust : {false, true}) {
            ConeMapOptions opt;
            opt.robust = robust;
            Field2D cones = cone_map(h, 0, opt, nullptr);
            int advanced = 0;
            for (int r = 0; r < 300; ++r) {
                const double px = u(rng) * n, py = u(rng) * n, pz = 7 + u(rng) * 4;
                const double ang = u(rng) * 6.283185307179586;
                const double dz = -(0.05 + u(rng) * 3); // horizontal length 1
                const double dx = std::cos(ang), dy = std::sin(ang);
                const double hit = first_hit(h, px, py, pz, dx, dy, dz);
                int steps = 0;
                const double t = march(cones, h, robust, px, py, pz, dx, dy, dz, steps);
                ASSERT_LE(t, hit + 1e-9) << "seed " << seed << " ray " << r << " robust " << robust;
                if (steps > 0 && t > 0.05 * std::min(hit, 1e9)) ++advanced;
            }
            // Exact box cones are 0 beside any higher neighbour (the apex sits on the
            // texel's own top), so only the robust map must march far on smooth fields.
            EXPECT_GT(advanced, robust && seed % 2 == 0 ? 15 : 0) << "cones too thin to be useful, robust " << robust;
        }
    }
}

TEST(DistanceMap, SweepsEqualBruteForce) {
    for (uint32_t seed = 0; seed < 4; ++seed) {
        Field2D h = random_heights(7 + int(seed), 6, seed, 40.0, seed % 2 == 0);
        Field3D a = distance_map(h, 0, 9, 0, 60, 1e4, nullptr);
        Field3D b = distance_map_brute_force(h, 0, 9, 0, 60, 1e4);
        for (size_t i = 0; i < a.voxel_count(); ++i) ASSERT_NEAR(a.channel(0)[i], b.channel(0)[i], 1e-4 * (1 + b.channel(0)[i])) << i;
    }
    Field2D low({{3, 3}}, 1, {{{0, 0}}, {{3, 3}}});
    std::fill(low.channel(0).begin(), low.channel(0).end(), -100.f); // no solid at all
    Field3D none = distance_map(low, 0, 4, 0, 10, 50, nullptr);
    for (float v : none.channel(0)) EXPECT_EQ(v, 50.0f);
    EXPECT_THROW(distance_map(low, 0, 4, 10, 0, 50, nullptr), Error);
}

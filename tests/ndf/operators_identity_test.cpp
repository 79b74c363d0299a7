// The fast warp and blur loops give the bytes of their direct forms
// (Field2D::sample_world per texel; the per-tap Gaussian sum), for any thread count.
#include "atlas/ndf/generators.h"
#include "atlas/ndf/operators.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <cstring>
#include <vector>

using namespace atlas;
using namespace atlas::ndf;

namespace {
Field2D direct_warp(const Field2D& in, const Field2D& warp, double amount, WrapMode wrap) {
    Field2D out(in.resolution(), in.channels(), in.bounds(), in.channel_names());
    const int cy = warp.channels() > 1 ? 1 : 0;
    for (int y = 0; y < in.height(); ++y)
        for (int x = 0; x < in.width(); ++x) {
            const Vec2d p = in.texel_center(x, y);
            const Vec2d q{{p[0] + amount * (2.0 * warp.at(0, x, y) - 1.0), p[1] + amount * (2.0 * warp.at(cy, x, y) - 1.0)}};
            for (int c = 0; c < in.channels(); ++c) out.at(c, x, y) = in.sample_world(c, q, wrap);
        }
    return out;
}
int wrap_index(int i, int n, WrapMode w) {
    if (w == WrapMode::Clamp) return std::clamp(i, 0, n - 1);
    const int m = i % n;
    return m < 0 ? m + n : m;
}
Field2D direct_blur(const Field2D& in, double sigma, WrapMode wrap) {
    const int rad = int(std::ceil(3 * sigma));
    std::vector<float> k(size_t(2 * rad + 1));
    double sum = 0;
    for (int i = -rad; i <= rad; ++i) sum += (k[size_t(i + rad)] = sigma > 0 ? float(std::exp(-0.5 * i * i / (sigma * sigma))) : 1.0f);
    for (auto& v : k) v = float(v / sum);
    const int w = in.width(), h = in.height();
    Field2D mid(in.resolution(), in.channels(), in.bounds()), out(in.resolution(), in.channels(), in.bounds(), in.channel_names());
    for (int c = 0; c < in.channels(); ++c)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                float s = 0;
                for (int i = -rad; i <= rad; ++i) s += k[size_t(i + rad)] * in.at(c, wrap_index(x + i, w, wrap), y);
                mid.at(c, x, y) = s;
            }
    for (int c = 0; c < in.channels(); ++c)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                float s = 0;
                for (int i = -rad; i <= rad; ++i) s += k[size_t(i + rad)] * mid.at(c, x, wrap_index(y + i, h, wrap));
                out.at(c, x, y) = s;
            }
    return out;
}
bool same_bytes(const Field2D& a, const Field2D& b) {
    if (a.resolution() != b.resolution() || a.channels() != b.channels()) return false;
    for (int c = 0; c < a.channels(); ++c)
        if (std::memcmp(a.channel(c).data(), b.channel(c).data(), a.channel(c).size() * sizeof(float)) != 0) return false;
    return true;
}
} // namespace

TEST(NdfFastPaths, WarpAndBlurEqualTheDirectFormsBitForBit) {
    const Box2d box{{{-300, 50}}, {{900, 830}}};
    const Vec2i res{{61, 47}}; // odd sizes: partial rows and rows shorter than the kernel
    Field2D in = noise2d(res, box, {{3, 2}}, 3, 0.5, 9, nullptr);
    Field2D two(res, 2, box, {"a", "b"});
    const Field2D n2 = noise2d(res, box, {{2, 3}}, 2, 0.5, 10, nullptr);
    std::copy(in.channel(0).begin(), in.channel(0).end(), two.channel(0).begin());
    std::copy(n2.channel(0).begin(), n2.channel(0).end(), two.channel(1).begin());
    in.at(0, 3, 4) = std::nanf("");
    for (WrapMode m : {WrapMode::Wrap, WrapMode::Clamp}) {
        for (double amount : {0.0, 37.5, 5000.0, 1e12})
            for (const Field2D* f : {&in, &two}) {
                EXPECT_TRUE(same_bytes(domain_warp(*f, two, amount, m, nullptr), direct_warp(*f, two, amount, m))) << amount;
                EXPECT_TRUE(same_bytes(domain_warp(*f, in, amount, m, nullptr), direct_warp(*f, in, amount, m))) << amount;
            }
        for (double sigma : {0.0, 0.4, 1.0, 2.5, 30.0}) // 30: radius 90 > the map
            for (const Field2D* f : {&in, &two}) EXPECT_TRUE(same_bytes(blur(*f, sigma, m, nullptr), direct_blur(*f, sigma, m))) << sigma;
    }
}

TEST(NdfFastPaths, SameBytesForAnyThreadCount) {
    const Box2d box{{{0, 0}}, {{60000, 60000}}};
    const Vec2i res{{300, 257}};
    auto run = [&] {
        std::vector<Field2D> v;
        v.push_back(noise2d(res, box, {{6, 6}}, 5, 0.55, 11, nullptr));
        v.push_back(noise2d(res, box, {{3, 3}}, 2, 0.5, 12, nullptr));
        v.push_back(domain_warp(v[0], v[1], 2500, WrapMode::Wrap, nullptr));
        v.push_back(blur(v[2], 3.0, WrapMode::Wrap, nullptr));
        v.push_back(blur(v[2], 2.0, WrapMode::Clamp, nullptr));
        return v;
    };
    std::vector<Field2D> one;
    {
        tbb::global_control gc(tbb::global_control::max_allowed_parallelism, 1);
        one = run();
    }
    const std::vector<Field2D> many = run();
    for (size_t i = 0; i < one.size(); ++i) EXPECT_TRUE(same_bytes(one[i], many[i])) << i;
}

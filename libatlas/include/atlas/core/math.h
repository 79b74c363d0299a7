// atlas/core/math.h - the few small vector types Atlas's public API uses.
// World coordinates are metres, in double; per-voxel data is float.
//
// Header-only.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>

namespace atlas {

template <typename T, int N>
struct Vec {
    std::array<T, N> v{};

    constexpr T& operator[](int i) { return v[static_cast<size_t>(i)]; }
    constexpr const T& operator[](int i) const { return v[static_cast<size_t>(i)]; }
    constexpr bool operator==(const Vec&) const = default;

    friend constexpr Vec operator+(Vec a, const Vec& b) { for (int i = 0; i < N; ++i) a[i] += b[i]; return a; }
    friend constexpr Vec operator-(Vec a, const Vec& b) { for (int i = 0; i < N; ++i) a[i] -= b[i]; return a; }
    friend constexpr Vec operator*(Vec a, T s) { for (int i = 0; i < N; ++i) a[i] *= s; return a; }
    friend constexpr Vec operator*(T s, Vec a) { return a * s; }
    friend constexpr Vec operator/(Vec a, T s) { for (int i = 0; i < N; ++i) a[i] /= s; return a; }
};

using Vec2d = Vec<double, 2>;
using Vec3d = Vec<double, 3>;
using Vec3f = Vec<float, 3>;
using Vec2i = Vec<int, 2>;
using Vec3i = Vec<int, 3>;

template <typename T, int N>
constexpr T dot(const Vec<T, N>& a, const Vec<T, N>& b) { T s = 0; for (int i = 0; i < N; ++i) s += a[i] * b[i]; return s; }
template <typename T, int N>
inline T length(const Vec<T, N>& a) { return std::sqrt(dot(a, a)); }
template <typename T>
constexpr Vec<T, 3> cross(const Vec<T, 3>& a, const Vec<T, 3>& b) {
    return {{a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]}};
}

// Axis-aligned world-space box [min, max] in metres.
template <int N>
struct Box {
    Vec<double, N> min{};
    Vec<double, N> max{};
    constexpr bool operator==(const Box&) const = default;
    Vec<double, N> size() const { return max - min; }
    bool valid() const {
        for (int i = 0; i < N; ++i) if (!(max[i] > min[i]) || !std::isfinite(min[i]) || !std::isfinite(max[i])) return false;
        return true;
    }
};
using Box2d = Box<2>;
using Box3d = Box<3>;

template <typename T>
constexpr T lerp(T a, T b, T t) { return a + (b - a) * t; }

} // namespace atlas

// Closed mesh primitives.
#include "atlas/volume/mesh_primitives.h"

#include "atlas/core/error.h"

#include <cmath>
#include <numbers>

namespace atlas::volume {
namespace {
Vec3f f3(double x, double y, double z) { return {{float(x), float(y), float(z)}}; }
void check_finite(const Vec3d& v, const char* what) {
    for (int i = 0; i < 3; ++i)
        if (!std::isfinite(v[i])) throw Error(std::string(what) + " must be finite");
}
} // namespace

Mesh make_box_mesh(Vec3d c, Vec3d hs) {
    check_finite(c, "box mesh: center");
    check_finite(hs, "box mesh: half size");
    for (int i = 0; i < 3; ++i)
        if (!(hs[i] > 0)) throw Error("box mesh: half size must be > 0 on every axis");
    Mesh m;
    for (int i = 0; i < 8; ++i) m.vertices.push_back(f3(c[0] + (i & 1 ? hs[0] : -hs[0]), c[1] + (i & 2 ? hs[1] : -hs[1]), c[2] + (i & 4 ? hs[2] : -hs[2])));
    const uint32_t q[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
    for (const auto& f : q) {
        m.triangles.push_back({f[0], f[1], f[2]});
        m.triangles.push_back({f[0], f[2], f[3]});
    }
    return m;
}

Mesh make_sphere_mesh(Vec3d c, double r, int stacks, int slices) {
    check_finite(c, "sphere mesh: center");
    if (!(r > 0) || !std::isfinite(r)) throw Error("sphere mesh: radius must be finite and > 0");
    if (stacks < 2 || slices < 3 || stacks > 4096 || slices > 4096) throw Error("sphere mesh: need 2..4096 stacks and 3..4096 slices");
    Mesh m;
    m.vertices.push_back(f3(c[0], c[1], c[2] + r));
    for (int i = 1; i < stacks; ++i) {
        const double th = std::numbers::pi * i / stacks;
        for (int j = 0; j < slices; ++j) {
            const double ph = 2 * std::numbers::pi * j / slices;
            m.vertices.push_back(f3(c[0] + r * std::sin(th) * std::cos(ph), c[1] + r * std::sin(th) * std::sin(ph), c[2] + r * std::cos(th)));
        }
    }
    m.vertices.push_back(f3(c[0], c[1], c[2] - r));
    const uint32_t south = uint32_t(m.vertices.size() - 1);
    auto ring = [&](int i, int j) { return uint32_t(1 + (i - 1) * slices + (j % slices)); };
    for (int j = 0; j < slices; ++j) m.triangles.push_back({0u, ring(1, j), ring(1, j + 1)});
    for (int i = 1; i + 1 < stacks; ++i)
        for (int j = 0; j < slices; ++j) {
            m.triangles.push_back({ring(i, j), ring(i + 1, j), ring(i + 1, j + 1)});
            m.triangles.push_back({ring(i, j), ring(i + 1, j + 1), ring(i, j + 1)});
        }
    for (int j = 0; j < slices; ++j) m.triangles.push_back({ring(stacks - 1, j), south, ring(stacks - 1, j + 1)});
    return m;
}

Mesh make_torus_mesh(Vec3d c, double R, double r, int nu, int nv) {
    check_finite(c, "torus mesh: center");
    if (!(r > 0) || !(R > r) || !std::isfinite(R)) throw Error("torus mesh: need major_radius > minor_radius > 0");
    if (nu < 3 || nv < 3 || nu > 4096 || nv > 4096) throw Error("torus mesh: segments must be in 3..4096");
    Mesh m;
    for (int i = 0; i < nu; ++i) {
        const double u = 2 * std::numbers::pi * i / nu;
        for (int j = 0; j < nv; ++j) {
            const double v = 2 * std::numbers::pi * j / nv;
            const double rr = R + r * std::cos(v);
            m.vertices.push_back(f3(c[0] + rr * std::cos(u), c[1] + rr * std::sin(u), c[2] + r * std::sin(v)));
        }
    }
    auto id = [&](int i, int j) { return uint32_t((i % nu) * nv + (j % nv)); };
    for (int i = 0; i < nu; ++i)
        for (int j = 0; j < nv; ++j) {
            m.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
            m.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
        }
    return m;
}

} // namespace atlas::volume

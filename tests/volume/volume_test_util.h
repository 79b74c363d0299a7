// Shapes shared by the volume tests.
#pragma once

#include "atlas/core/field.h"

#include <cmath>
#include <random>

namespace atlas::volume::test {

// Density of a sphere that is linear in the distance across the surface
// (0.5 at radius R, ramping over 2 voxels), so its iso-0.5 crossings lie on
// the sphere up to curvature.
inline Field3D sphere_density(Vec3i res, Box3d box, Vec3d c, double r) {
    Field3D f(res, 1, box);
    const double h = f.voxel_size()[0];
    for (int z = 0; z < res[2]; ++z)
        for (int y = 0; y < res[1]; ++y)
            for (int x = 0; x < res[0]; ++x) {
                const Vec3d p = f.voxel_center(x, y, z);
                const double d = length(p - c) - r;
                f.at(0, x, y, z) = float(std::clamp(0.5 - d / (2 * h), 0.0, 1.0));
            }
    return f;
}

// Random blobs: a sum of Gaussians at random places (seeded).
inline Field3D random_blobs(Vec3i res, Vec3d voxel, unsigned seed, int blobs = 5) {
    Box3d box{{{0, 0, 0}}, {{res[0] * voxel[0], res[1] * voxel[1], res[2] * voxel[2]}}};
    Field3D f(res, 1, box);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0, 1);
    for (int b = 0; b < blobs; ++b) {
        const Vec3d c{{u(rng) * box.max[0], u(rng) * box.max[1], u(rng) * box.max[2]}};
        const double r = (0.08 + 0.2 * u(rng)) * std::min({box.max[0], box.max[1], box.max[2]}) + voxel[0];
        for (int z = 0; z < res[2]; ++z)
            for (int y = 0; y < res[1]; ++y)
                for (int x = 0; x < res[0]; ++x) {
                    const Vec3d p = f.voxel_center(x, y, z) - c;
                    f.at(0, x, y, z) += float(std::exp(-dot(p, p) / (r * r)));
                }
    }
    return f;
}

} // namespace atlas::volume::test

#include "atlas/core/geometry.h"

#include <numbers>

namespace atlas::volume::test {

// Closed UV sphere, outward-facing triangles.
inline Mesh uv_sphere(Vec3d c, double r, int stacks = 24, int slices = 48) {
    Mesh m;
    m.vertices.push_back({{float(c[0]), float(c[1]), float(c[2] + r)}});
    for (int i = 1; i < stacks; ++i) {
        const double th = std::numbers::pi * i / stacks;
        for (int j = 0; j < slices; ++j) {
            const double ph = 2 * std::numbers::pi * j / slices;
            m.vertices.push_back({{float(c[0] + r * std::sin(th) * std::cos(ph)), float(c[1] + r * std::sin(th) * std::sin(ph)),
                                   float(c[2] + r * std::cos(th))}});
        }
    }
    m.vertices.push_back({{float(c[0]), float(c[1]), float(c[2] - r)}});
    const uint32_t south = uint32_t(m.vertices.size() - 1);
    auto ring = [&](int i, int j) { return uint32_t(1 + (i - 1) * slices + ((j % slices + slices) % slices)); };
    for (int j = 0; j < slices; ++j) m.triangles.push_back({0u, ring(1, j), ring(1, j + 1)});
    for (int i = 1; i + 1 < stacks; ++i)
        for (int j = 0; j < slices; ++j) {
            m.triangles.push_back({ring(i, j), ring(i + 1, j), ring(i + 1, j + 1)});
            m.triangles.push_back({ring(i, j), ring(i + 1, j + 1), ring(i, j + 1)});
        }
    for (int j = 0; j < slices; ++j) m.triangles.push_back({ring(stacks - 1, j), south, ring(stacks - 1, j + 1)});
    return m;
}

// Axis-aligned closed box, outward-facing.
inline Mesh box_mesh(Vec3d lo, Vec3d hi) {
    Mesh m;
    for (int i = 0; i < 8; ++i)
        m.vertices.push_back({{float(i & 1 ? hi[0] : lo[0]), float(i & 2 ? hi[1] : lo[1]), float(i & 4 ? hi[2] : lo[2])}});
    const uint32_t q[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
    for (const auto& f : q) {
        m.triangles.push_back({f[0], f[1], f[2]});
        m.triangles.push_back({f[0], f[2], f[3]});
    }
    return m;
}

} // namespace atlas::volume::test

// Shapes shared by the volume tests.
#pragma once

#include "atlas/core/field.h"
#include "atlas/volume/mesh_primitives.h"

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

// Test meshes come from the library's primitives (they are inputs here, not
// what is under test; mesh_primitives has its own tests).
inline Mesh uv_sphere(Vec3d c, double r, int stacks = 24, int slices = 48) { return make_sphere_mesh(c, r, stacks, slices); }

// Axis-aligned closed box, outward-facing.
inline Mesh box_mesh(Vec3d lo, Vec3d hi) { return make_box_mesh((lo + hi) * 0.5, (hi - lo) * 0.5); }

} // namespace atlas::volume::test

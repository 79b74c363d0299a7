// atlas/volume/mesh_primitives.h - closed, outward-oriented meshes built in code
// (for graphs that grow a cloud inside a shape, and for tests). Metres. Pure.
#pragma once

#include "atlas/core/geometry.h"

namespace atlas::volume {

// Axis-aligned box: 12 triangles. Throws atlas::Error on a negative or non-finite size.
Mesh make_box_mesh(Vec3d center, Vec3d half_size);
// UV sphere: stacks >= 2, slices >= 3.
Mesh make_sphere_mesh(Vec3d center, double radius, int stacks = 24, int slices = 48);
// Torus around the z axis: major radius R > minor radius r > 0; segments >= 3 each way.
Mesh make_torus_mesh(Vec3d center, double major_radius, double minor_radius, int major_segments = 48, int minor_segments = 24);

} // namespace atlas::volume

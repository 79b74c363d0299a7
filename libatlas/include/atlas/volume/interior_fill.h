// atlas/volume/interior_fill.h - grow a cloud inside a closed mesh: TetGen
// tetrahedralises the interior, one sample is placed in every tetrahedron
// (at a point drawn from hash(seed, tet index), uniform in the tet), and each
// sample's radius is its local thickness (distance to the surface, from a
// CGAL AABB tree) times radius_scale. Feed the points to splat_points
// (metaballs) to get billowy puffs that fill the shape, large in thick parts
// and small near thin ones - the way artists grew clouds from game models.
// Deterministic (TetGen is serial; sampling is hash-keyed). Thread-safe.
#pragma once

#include "atlas/core/geometry.h"

#include <cstdint>

namespace atlas::volume {

struct InteriorFillOptions {
    // Sets TetGen's maximum tetrahedron volume to (enclosed volume / target_samples),
    // 1..10^7. TetGen's quality refinement and the surface triangulation add
    // tetrahedra, so the sample count is usually higher (a 4096-triangle torus
    // with target 250 gave 7849).
    int target_samples = 2000;
    double radius_scale = 0.9;  // sample radius = thickness * radius_scale (> 0)
    double min_radius = 0;      // metres, lower clamp on radii (>= 0)
    uint32_t seed = 1;
};

struct InteriorFillStats {
    uint64_t tetrahedra = 0;
    double interior_volume = 0; // m^3, from the tetrahedra
    double max_thickness = 0;   // m
};

// Returns points with attributes "radius" (m) and "thickness" (m). The mesh
// must be closed and free of self-intersections (repair_mesh first); throws
// atlas::Error saying so when TetGen rejects it, and on invalid options or an
// empty / non-finite mesh.
Points fill_mesh_interior(const Mesh& mesh, const InteriorFillOptions& options = {}, InteriorFillStats* stats = nullptr);

} // namespace atlas::volume

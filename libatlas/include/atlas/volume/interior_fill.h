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
    // The number of samples returned, exactly, 1..10^7. Up to 20,000 they are
    // farthest-point selected from 8x as many uniform candidates (spacing about
    // (volume / target)^(1/3)); above that the candidates are returned as drawn
    // (uniform, unspread: the selection would cost target x 8 target).
    // (Before node version 2 this was TetGen's volume bound, and TetGen's
    // refinement gave 3-230x more samples than asked for.)
    int target_samples = 2000;
    double radius_scale = 0.9;  // sample radius = thickness * radius_scale (> 0)
    double min_radius = 0;      // metres, lower clamp on radii (>= 0)
    uint32_t seed = 1;
};

struct InteriorFillStats {
    uint64_t tetrahedra = 0;    // TetGen's tetrahedra (the volume drawn from)
    uint64_t candidates = 0;    // uniform candidates drawn
    uint64_t samples = 0;       // samples returned (= target_samples)
    double interior_volume = 0; // m^3, from the tetrahedra
    double max_thickness = 0;   // m
};

// Returns points with attributes "radius" (m) and "thickness" (m). The mesh
// must be closed and free of self-intersections (repair_mesh first); throws
// atlas::Error saying so when TetGen rejects it, and on invalid options or an
// empty / non-finite mesh.
Points fill_mesh_interior(const Mesh& mesh, const InteriorFillOptions& options = {}, InteriorFillStats* stats = nullptr);

} // namespace atlas::volume
